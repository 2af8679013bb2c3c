// Torn pieces come apart: once the triangle mesh has parted, no constraint ties its pieces together
// (markUnsupported in sim_bodies.h: an edge no live triangle holds, a bend over such an edge, a
// diagonal across a lost triangle, a tri-bend over one), so the pieces fall apart; folding tears
// nothing.
#include <algorithm>
#include <map>
#include <numeric>

#include "common/sim_helpers.h"
#include "cpu/cpu_solver.h"

using namespace tender;
using namespace tender::test;

namespace {

// Particle count of each connected piece (over the live constraints), largest first.
std::vector<uint32_t> pieces(const SimState& s) {
  std::vector<uint32_t> parent(s.pos.size());
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (const ColorRange& range : s.colors)
    for (uint32_t k = range.first; k < range.first + range.count; ++k)
      parent[find(s.constraints[k].a)] = find(s.constraints[k].b);
  std::map<uint32_t, uint32_t> size;
  for (uint32_t i = 0; i < parent.size(); ++i) ++size[find(i)];
  std::vector<uint32_t> out;
  for (auto& [root, n] : size) out.push_back(n);
  std::sort(out.rbegin(), out.rend());
  return out;
}

} // namespace

TEST(Pieces, ATearAcrossTheSheetLeavesTwoPiecesThatFallApart) {
  for (const char* name : {"tender", "crumple"}) {
    const SimParams p = preset(name, {"wind=off", "cols=16", "rows=24"});
    CpuSolver solver;
    Simulation sim(p, solver);
    run(sim, 2);
    // Tear across: the lower half drops four spacings at once, the structural and bend
    // constraints between rows 11 and 12 stretch beyond the tear factor and tear
    for (uint32_t i = 12 * 16; i < 24 * 16; ++i) {
      solver.positions()[i].y -= 4.0f * p.spacing;
      solver.previous()[i].y -= 4.0f * p.spacing;
    }
    const shaderio::SimUniforms u = sim.makeUniforms();
    ASSERT_GT(solver.markTears(u), 0u);
    ASSERT_GT(solver.markUnsupported(u), 0u) << name << ": the quads the tear cut keep their diagonals";
    solver.compact();
    SimState s;
    solver.readback(s);
    std::vector<uint32_t> parts = pieces(s);
    ASSERT_EQ(parts.size(), 2u) << name;
    EXPECT_EQ(parts[0], 12u * 16u);
    EXPECT_EQ(parts[1], 12u * 16u);
    // Two seconds later the lower piece has fallen away from the upper one (crumple falls slowly:
    // gravity 0.5), still in one piece
    s = run(sim, int(2.0f * p.tick_hz));
    parts = pieces(s);
    ASSERT_EQ(parts.size(), 2u) << name;
    float gap = INFINITY;
    for (uint32_t a = 0; a < 12 * 16; ++a)
      for (uint32_t b = 12 * 16; b < 24 * 16; ++b)
        gap = std::min(gap, glm::distance(glm::vec3(s.pos[a]), glm::vec3(s.pos[b])));
    std::printf("%s: the pieces are %.2f apart after 2 s\n", name, gap);
    EXPECT_GT(gap, 5.0f * p.spacing) << name;
  }
}

TEST(Pieces, FoldingTearsNothing) {
  TENDER_ONE_THREAD_TEST();
  for (const char* name : {"tender", "crumple"}) {
    const SimParams p = preset(name, {"wind=off", "cols=16", "rows=24"});
    CpuSolver solver;
    Simulation sim(p, solver);
    // Bring the bottom-left corner up over the sheet to the top-right, slowly: a diagonal fold
    std::string text = "0 grab particle 368\n";
    const glm::vec3 from = glm::vec3(solver.positions()[368]),
                    to = glm::vec3(solver.positions()[15]) + glm::vec3(0, -0.2f, 0.3f);
    for (int t = 1; t <= 150; ++t) {
      const glm::vec3 q =
          from + (to - from) * (float(t) / 150.0f) + glm::vec3(0, 0, 1.5f * std::sin(3.14159f * float(t) / 150.0f));
      text += std::to_string(t) + " move " + std::to_string(q.x) + " " + std::to_string(q.y) + " " +
              std::to_string(q.z) + "\n";
    }
    sim.setScript(script(text.c_str()));
    const SimState s = run(sim, 240);
    EXPECT_EQ(tornCount(s), 0u) << name;
    EXPECT_EQ(pieces(s).size(), 1u) << name;
    EXPECT_LT(glm::distance(glm::vec3(s.pos[368]), to), 0.5f) << name << ": the corner did not fold over";
  }
}

// A hard pull in several directions, then a release, with the wind off: within 10 s the sheet
// hangs from its pins again, no particle above them (it used to stay folded up over the pin line,
// held by the piece the pull had torn but the diagonals still tied on).
TEST(Pieces, AHardPullLeavesNothingAboveThePins) {
  const SimParams p = cloth();
  CpuSolver solver;
  Simulation sim(p, solver);
  sim.setScript(script("0 wind off\n0 grab particle 1520\n2 move 0 -12 0\n4 move 8 -14 6\n6 move -8 -16 -6\n"
                       "9 move 0 -30 0\n60 release\n"));
  const SimState s = run(sim, 60 + int(10.0f * p.tick_hz));
  float pin_y = -INFINITY, top = -INFINITY;
  for (uint32_t i = 0; i < s.pos.size(); ++i) {
    if (sim.topology().rest_pos[i].w > 0.5f) pin_y = std::max(pin_y, s.pos[i].y);
    top = std::max(top, s.pos[i].y);
  }
  EXPECT_GT(tornCount(s), 0u);
  EXPECT_LE(top, pin_y + 1e-3f) << "a particle is " << top - pin_y << " above the pins";
}

// A piece of the mesh is free: through a hard yank of each preset that tears, and after it, no live
// constraint joins particles of two pieces of the live triangle mesh (it used to leave bends over
// cut edges and diagonals across lost triangles, which kept a torn-out shred hanging on the sheet).
TEST(Pieces, NoConstraintTiesTwoPiecesOfTheMesh) {
  for (const char* name : {"tender", "crumple"}) {
    const SimParams p = preset(name, {"wind=off", "cols=24", "rows=36"});
    CpuSolver solver;
    Simulation sim(p, solver);
    sim.setScript(script("0 grab particle 850\n2 move 0 -12 0\n4 move 8 -14 6\n6 move -8 -16 -6\n9 move 0 -30 0\n"
                         "30 release\n"));
    uint32_t ties = 0, torn = 0;
    for (int t = 0; t < 120; t += 10) {
      const SimState s = run(sim, 10);
      ties += tiesAcrossPieces(s);
      torn = tornCount(s);
    }
    EXPECT_GT(torn, 0u) << name << ": the yank tears";
    EXPECT_EQ(ties, 0u) << name << ": live constraints tie pieces of the mesh together";
  }
}
