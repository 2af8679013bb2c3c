#include <gtest/gtest.h>

#include <set>

#include "common/sim_helpers.h"
#include "core/sheet.h"

using namespace tender;
using namespace tender::test;

TEST(Sheet, CountsMatchTheSpecFor32x48) {
  SheetTopology t = buildSheet(clothWithContact());
  EXPECT_EQ(t.particleCount(), 1536u);
  EXPECT_EQ(t.kind_counts[SIM_KIND_STRUCTURAL], 2992u);
  EXPECT_EQ(t.kind_counts[SIM_KIND_SHEAR], 2914u);
  EXPECT_EQ(t.kind_counts[SIM_KIND_BEND], 2912u);
  EXPECT_EQ(t.kind_counts[SIM_KIND_TRIBEND], 0u);
  EXPECT_EQ(t.triangleCount(), 2914u);
  EXPECT_EQ(t.constraintCount(), 2992u + 2914u + 2912u);
}

TEST(Sheet, CrumpleHasHinges) {
  SheetTopology t = buildSheet(crumpleSheet());
  EXPECT_EQ(t.particleCount(), 2400u);
  EXPECT_EQ(t.kind_counts[SIM_KIND_BEND], 0u);
  EXPECT_EQ(t.kind_counts[SIM_KIND_TRIBEND], 0u);
  // One per interior edge: (W-1)(H-2) across rows, (W-2)(H-1) across columns, a diagonal per quad;
  // the quads' other diagonal is gone (the sheet folds there)
  EXPECT_EQ(t.kind_counts[SIM_KIND_HINGE], 39u * 58u + 38u * 59u + 39u * 59u);
  EXPECT_EQ(t.kind_counts[SIM_KIND_SHEAR], 39u * 59u);
  EXPECT_EQ(t.hinge_first + t.hingeCount(), t.constraintCount());
  EXPECT_EQ(sheetCounts(crumpleSheet()).constraints, t.constraintCount());
  // Each hinge's two triangles are the two of gridTriangle that hold its edge and its corners
  for (uint32_t k = 0; k < t.hingeCount(); ++k) {
    const glm::uvec4 q = shaderio::gridHinge(k, t.cols, t.rows);
    const glm::uvec2 tris = shaderio::hingeTriangles(k, t.cols, t.rows);
    auto has = [&](uint32_t tri, glm::uvec3 want) {
      const glm::uvec3 c = shaderio::gridTriangle(tri, t.cols);
      // the same three corners in the same cyclic order (counter-clockwise)
      return (c == want) || (c == glm::uvec3(want.y, want.z, want.x)) || (c == glm::uvec3(want.z, want.x, want.y));
    };
    ASSERT_TRUE(has(tris.x, glm::uvec3(q.x, q.y, q.z))) << k;
    ASSERT_TRUE(has(tris.y, glm::uvec3(q.y, q.x, q.w))) << k;
  }
}

// No two constraints of one colour share a particle; ranges tile the array.
static void expectValidColoring(const SheetTopology& t) {
  uint32_t next = 0;
  for (const ColorRange& r : t.colors) {
    EXPECT_EQ(r.first, next);
    next = r.first + r.count;
    std::set<uint32_t> seen;
    for (uint32_t k = r.first; k < r.first + r.count; ++k) {
      EXPECT_TRUE(seen.insert(t.constraints[k].a).second) << "colour shares particle " << t.constraints[k].a;
      EXPECT_TRUE(seen.insert(t.constraints[k].b).second) << "colour shares particle " << t.constraints[k].b;
    }
  }
  EXPECT_EQ(next, t.constraintCount());
}

TEST(Coloring, NoSharedParticleWithinColor) {
  for (auto [w, h] : {std::pair{1u, 2u}, {2u, 2u}, {37u, 53u}, {32u, 48u}, {1u, 1u}, {5u, 1u}}) {
    for (const char* preset : {"tender", "crumple"}) {
      SimParams p = *presetParams(preset);
      p.cols = w;
      p.rows = h;
      SCOPED_TRACE(std::string(preset) + " " + std::to_string(w) + "x" + std::to_string(h));
      expectValidColoring(buildSheet(p));
    }
  }
}

TEST(Coloring, AColourHoldsItsEdgesFirst) {
  // The shorten stage of the CPU visits the run of structural edges at the head of each colour
  // (CpuSolver::shortenColors): every kind of sheet keeps them there (the compaction keeps the order)
  for (const char* preset : {"tender", "crumple", "paper"})
    for (const char* extra : {"", "tri_bend", "shear"}) {
      SimParams p = *presetParams(preset);
      if (std::string(extra) == "tri_bend") p.tri_bend = true, p.bend = true;
      if (std::string(extra) == "shear") p.shear = true, p.dihedral = false;
      const SheetTopology t = buildSheet(p);
      uint32_t edges = 0;
      for (const ColorRange& range : t.colors) {
        bool past = false;
        for (uint32_t k = range.first; k < range.first + range.count; ++k) {
          const bool edge = constraintKind(t.constraints[k]) == SIM_KIND_STRUCTURAL;
          EXPECT_FALSE(edge && past) << preset << " " << extra << ": an edge after another kind in colour at "
                                     << range.first;
          past = past || !edge;
          edges += edge;
        }
      }
      EXPECT_EQ(edges, t.kind_counts[SIM_KIND_STRUCTURAL]) << preset << " " << extra;
    }
}

TEST(Coloring, GridNeedsTwelveColours) {
  // An interior particle has 12 constraints, so 12 colours is optimal; greedy reaches it.
  EXPECT_EQ(buildSheet(clothWithContact()).colorCount(), 12u);
}

TEST(Sheet, AdjacencyIsSymmetricAndFromConstraints) {
  SimParams p = clothWithContact();
  p.cols = 7;
  p.rows = 9;
  SheetTopology t = buildSheet(p);
  for (auto& c : t.constraints) {
    EXPECT_TRUE(t.adjacent(c.a, c.b));
    EXPECT_TRUE(t.adjacent(c.b, c.a));
  }
  EXPECT_FALSE(t.adjacent(0, 7 * 2 + 1)); // (1,2): a knight's move away, not connected
}

TEST(Sheet, TrianglesAreCounterClockwiseFromFront) {
  SheetTopology t = buildSheet(clothWithContact());
  for (auto& tri : t.triangles) {
    glm::vec3 a(t.rest_pos[tri.x]), b(t.rest_pos[tri.y]), c(t.rest_pos[tri.z]);
    EXPECT_GT(glm::cross(b - a, c - a).z, 0.0f);
  }
}

TEST(Sheet, PinsAndPlacement) {
  SimParams p = clothWithContact();
  SheetTopology t = buildSheet(p);
  std::vector<uint32_t> pins;
  for (uint32_t i = 0; i < t.particleCount(); ++i)
    if (t.rest_pos[i].w > 0.5f) pins.push_back(i);
  EXPECT_EQ(pins, (std::vector<uint32_t>{0, 16, 31}));
  float lowest = 1e9f;
  for (auto& r : t.rest_pos) lowest = std::min(lowest, r.y);
  EXPECT_GT(lowest, p.floor_y + 1.0f);
  EXPECT_TRUE(buildSheet(crumpleSheet()).rest_pos[39].w > 0.5f);
}
