// Hinges and creases: the signed dihedral angle against closed forms and finite differences, a
// fold that stays in paper and springs back in cloth, wind that creases nothing, creases that do
// not depend on the iteration count, and every value finite through a flat fold.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>

#include "common/sheet_scenes.h"
#include "common/sim_helpers.h"
#include "core/intersections.h"
#include "core/stats.h"
#include "cpu/cpu_solver.h"

namespace tender::test {
namespace {

using shaderio::gridHinge;
using shaderio::hingeAngle;
using shaderio::HingeAngle;
using shaderio::wrapAngle;

/// The hinge angle in double precision from its definition (atan2 of (nb x na) . e and na . nb |e|).
double angleOf(const glm::dvec3& u, const glm::dvec3& v, const glm::dvec3& a, const glm::dvec3& b) {
  const glm::dvec3 e = v - u, na = glm::cross(e, a - u), nb = glm::cross(u - v, b - v);
  return std::atan2(glm::dot(glm::cross(nb, na), e), glm::dot(na, nb) * glm::length(e));
}

/// A hinge along x from (0,0,0) to (1,0,0): corner a at (0.4, 1, 0) in the plane, corner b folded
/// by `fold` radians about the edge from its flat place (0.6, -1, 0), towards +z for fold > 0.
std::array<glm::vec3, 4> foldedHinge(double fold) {
  const glm::vec3 u(0.0f), v(1.0f, 0.0f, 0.0f), a(0.4f, 1.0f, 0.0f);
  const glm::vec3 b(0.6f, float(-std::cos(fold)), float(std::sin(fold)));
  return {u, v, a, b};
}

TEST(Hinge, TheAngleIsTheSignedFoldAndAtan2IsWithinAMicroradian) {
  for (double deg = -179.0; deg <= 180.0; deg += 0.5) {
    const auto h = foldedHinge(deg / kDeg);
    const HingeAngle g = hingeAngle(h[0], h[1], h[2], h[3], true);
    ASSERT_TRUE(g.valid) << deg;
    EXPECT_NEAR(g.angle * kDeg, deg, 1e-4) << deg;
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> any(-1e3f, 1e3f);
  double worst = 0.0;
  for (int k = 0; k < 200000; ++k) {
    const float y = any(rng) * (k % 3 == 0 ? 1e-4f : 1.0f), x = any(rng);
    worst = std::max(worst, std::abs(double(shaderio::simAtan2(y, x)) - std::atan2(double(y), double(x))));
  }
  std::printf("simAtan2: largest error %.3g rad over 200000 points\n", worst);
  EXPECT_LT(worst, 1e-6);
  EXPECT_EQ(shaderio::simAtan2(0.0f, 0.0f), 0.0f);
  EXPECT_FLOAT_EQ(shaderio::simAtan2(0.0f, -1.0f), 3.14159265f);
}

TEST(Hinge, TheGradientIsTheAnglesDerivative) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> jitter(-0.3f, 0.3f);
  for (int trial = 0; trial < 200; ++trial) {
    auto h = foldedHinge(double(trial % 40 - 20) * 0.15);
    for (glm::vec3& p : h) p += glm::vec3(jitter(rng), jitter(rng), jitter(rng));
    const HingeAngle g = hingeAngle(h[0], h[1], h[2], h[3], true);
    ASSERT_TRUE(g.valid);
    const glm::vec3 grads[4] = {g.gu, g.gv, g.ga, g.gb};
    EXPECT_LT(glm::length(g.gu + g.gv + g.ga + g.gb), 1e-4f); // a translation turns nothing
    for (int c = 0; c < 4; ++c)
      for (int axis = 0; axis < 3; ++axis) {
        glm::dvec3 p[4] = {h[0], h[1], h[2], h[3]};
        const double step = 1e-6;
        p[c][axis] += step;
        const double up = angleOf(p[0], p[1], p[2], p[3]);
        p[c][axis] -= 2 * step;
        const double down = angleOf(p[0], p[1], p[2], p[3]);
        const double numeric = (up - down) / (2 * step);
        EXPECT_NEAR(grads[c][axis], numeric, 1e-3 * (1.0 + std::abs(numeric))) << trial << " corner " << c;
      }
  }
}

TEST(Hinge, AFlatFoldAndDegenerateTrianglesStayFinite) {
  // Folds of +-179 and 180 degrees, and through 180; a corner on the edge's line, an edge of no
  // length: every correction and multiplier finite.
  std::vector<std::array<glm::vec3, 4>> cases;
  for (double deg : {179.0, -179.0, 180.0, -180.0, 179.999, -179.999}) cases.push_back(foldedHinge(deg / kDeg));
  cases.push_back({glm::vec3(0.0f), glm::vec3(1, 0, 0), glm::vec3(0.5f, 0, 0), glm::vec3(0.5f, -1, 0)});
  cases.push_back({glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(0.5f, 1, 0), glm::vec3(0.5f, -1, 0)});
  cases.push_back({glm::vec3(0.0f), glm::vec3(1, 0, 0), glm::vec3(0.4f, 1e-20f, 0), glm::vec3(0.5f, -1, 0)});
  for (const auto& h : cases)
    for (float rest : {0.0f, 3.1415926f, -3.1415926f, 1.0f})
      for (float alpha : {0.0f, 1e-3f, 1e6f}) {
        glm::vec4 p[4];
        for (int c = 0; c < 4; ++c) p[c] = glm::vec4(h[c], 1.0f);
        float lambda = 0.0f;
        for (int it = 0; it < 16; ++it) {
          const shaderio::HingeDelta d = shaderio::solveHinge(p[0], p[1], p[2], p[3], rest, alpha, lambda);
          p[0] += glm::vec4(d.du, 0.0f);
          p[1] += glm::vec4(d.dv, 0.0f);
          p[2] += glm::vec4(d.da, 0.0f);
          p[3] += glm::vec4(d.db, 0.0f);
          lambda = d.lambda;
          ASSERT_TRUE(std::isfinite(lambda));
          for (const glm::vec4& q : p)
            for (int k = 0; k < 3; ++k) ASSERT_TRUE(std::isfinite(q[k])) << rest << " " << alpha;
        }
        const glm::vec4 st = shaderio::creaseReturn(glm::vec4(rest, 0.0f, lambda, 0.0f), 3.1415927f, 0.2f, 0.5f);
        ASSERT_TRUE(std::isfinite(st.x) && std::isfinite(st.y));
        ASSERT_LE(std::abs(st.x), 3.1415927f);
      }
}

TEST(Hinge, TheReturnMapMovesTheRestAngleByWhatPassesTheYield) {
  // |d| = 0.5 past a yield of 0.2 with hardening 0.5: the rest angle moves 0.3 / 1.5 = 0.2 and the
  // yield grows by 0.1; within the yield nothing moves; across +-pi the shorter way round.
  glm::vec4 st = shaderio::creaseReturn(glm::vec4(0.0f), 0.5f, 0.2f, 0.5f);
  EXPECT_FLOAT_EQ(st.x, 0.2f);
  EXPECT_FLOAT_EQ(st.y, 0.1f);
  EXPECT_EQ(shaderio::creaseReturn(st, 0.45f, 0.2f, 0.5f), st); // 0.25 from rest, yield 0.3
  st = shaderio::creaseReturn(glm::vec4(3.0f, 0.0f, 0.0f, 0.0f), -3.0f, 0.1f, 0.0f);
  EXPECT_NEAR(st.x, 3.0 + (2 * 3.14159265358979 - 6.0 - 0.1) - 2 * 3.14159265358979, 1e-5); // 0.183 on, past pi
  EXPECT_EQ(shaderio::creaseReturn(glm::vec4(0.0f), 1.0f, 0.0f, 0.0f), glm::vec4(0.0f));    // yield 0: elastic
}

/// Per interior row j of the grid, the median |angle| (degrees) of the hinges across its row edges:
/// of their geometry (`rest` false) or of their rest angles.
std::vector<double> rowMedians(const SimState& s, const SimParams& p, bool rest) {
  std::vector<double> medians(p.rows, 0.0);
  for (uint32_t j = 1; j + 1 < p.rows; ++j) {
    std::vector<double> row;
    for (uint32_t i = 0; i + 1 < p.cols; ++i) {
      const uint32_t k = (j - 1) * (p.cols - 1) + i;
      if (rest) {
        row.push_back(std::abs(double(s.hinges.at(k).x)) * kDeg);
        continue;
      }
      const glm::uvec4 q = gridHinge(k, p.cols, p.rows);
      const HingeAngle g =
          hingeAngle(glm::vec3(s.pos[q.x]), glm::vec3(s.pos[q.y]), glm::vec3(s.pos[q.z]), glm::vec3(s.pos[q.w]), false);
      row.push_back(g.valid ? std::abs(double(g.angle)) * kDeg : 0.0);
    }
    std::nth_element(row.begin(), row.begin() + row.size() / 2, row.end());
    medians[j] = row[row.size() / 2];
  }
  return medians;
}

struct FoldResult {
  double fold_line_deg = 0.0;  ///< the largest median |angle| of a row: the fold line's
  double crease_deg = 0.0;     ///< the largest median |rest angle| of a row (0 without hinges)
  double crease_sum_deg = 0.0; ///< the sum of the rows' median |rest angle|: the whole crease, however wide
  float most_stretch = 0.0f;   ///< the largest structural stretch at any tick
  uint32_t nans = 0;
};

FoldResult foldAndUnfold(const SimParams& p, double rest_s = 5.0, double carry_s = 1.5) {
  CpuSolver solver;
  Simulation sim(p, solver);
  auto [text, ticks] = foldScript(p, rest_s, carry_s);
  sim.setScript(script(text.c_str()));
  FoldResult r;
  SimState s;
  for (int t = 0; t < ticks; ++t) {
    sim.tick();
    solver.readback(s);
    const SheetStats st = computeStats(s, p.substepDt());
    r.most_stretch = std::max(r.most_stretch, st.max_stretch);
    r.nans += st.nan_count;
  }
  for (double m : rowMedians(s, p, false)) r.fold_line_deg = std::max(r.fold_line_deg, m);
  if (!s.hinges.empty())
    for (double m : rowMedians(s, p, true)) r.crease_deg = std::max(r.crease_deg, m), r.crease_sum_deg += m;
  std::printf("%s: fold line %.1f deg, crease %.1f deg (%.1f over its rows), most stretch %.4f\n", p.preset.c_str(),
              r.fold_line_deg, r.crease_deg, r.crease_sum_deg, double(r.most_stretch));
  return r;
}

TEST(Crease, AFoldLeavesACreaseInPaper) {
  TENDER_ONE_THREAD_TEST();
  // (The crease tests and the limit's scenes below are paper without contact: their subject is the
  // hinges and the rings; contact's own tests and the stretch test run the presets' contact.)
  const SimParams crumple = flatSheet(paperSheet(), {"cols=20", "rows=30"});
  const FoldResult r = foldAndUnfold(crumple);
  EXPECT_EQ(r.nans, 0u);
  EXPECT_GE(r.fold_line_deg, 20.0);
  EXPECT_GE(r.crease_deg, 20.0);
  // The stretch limit holds the edges within 1 % of rest (1.07 without it)
  EXPECT_LE(r.most_stretch, 1.03f);
  // The receipt: a fold held by its edge alone (nothing presses it) creases its hinges by some 30
  // degrees; on the floor its 15 cm halves, three times paper's elastic length (D / rho g)^(1/3) =
  // 5 cm, lie flat and open the crease to a few degrees.
  const FoldResult receipt = foldAndUnfold(flatSheet(receiptSheet(), {}));
  EXPECT_EQ(receipt.nans, 0u);
  EXPECT_GE(receipt.crease_deg, 20.0);
  EXPECT_GE(receipt.fold_line_deg, 4.0);
}

TEST(Crease, AnElasticSheetIsFlatAgain) {
  TENDER_ONE_THREAD_TEST();
  // The tender preset's skip-one bending, and its hinges without creases
  for (const char* bending : {"dihedral=off", "dihedral=on"}) {
    const SimParams p = flatSheet("tender", {"cols=16", "rows=24", bending, "crease_yield=0"});
    const FoldResult r = foldAndUnfold(p);
    EXPECT_EQ(r.nans, 0u) << bending;
    EXPECT_LT(r.fold_line_deg, 2.0) << bending;
    EXPECT_EQ(r.crease_deg, 0.0) << bending;
  }
}

TEST(Crease, CreasesDoNotDependOnTheIterationCount) {
  TENDER_ONE_THREAD_TEST();
  // The return map runs once per substep and the hinges' stiffness is a compliance, so a fold makes
  // the same crease with 4 and with 16 iterations; what differs is the structural constraints'
  // stiffness, which shapes the fold a little
  FoldResult r[2];
  for (int k = 0; k < 2; ++k)
    r[k] = foldAndUnfold(flatSheet(paperSheet(), {"cols=20", "rows=30", k == 0 ? "iterations=4" : "iterations=16"}),
                         0.5, 3.0);
  EXPECT_GE(r[0].crease_deg, 15.0);
  EXPECT_NEAR(r[0].crease_sum_deg, r[1].crease_sum_deg, 0.05 * r[1].crease_sum_deg);
  EXPECT_NEAR(r[0].crease_deg, r[1].crease_deg, 6.0);
}

TEST(Crease, WindCreasesNothing) {
  TENDER_ONE_THREAD_TEST();
  // The crumple sheet hanging from its corners in ten seconds of strong wind
  CpuSolver solver;
  const SimParams p = paperSheet({"cols=20", "rows=30", "wind=on", "wind_strength=3"});
  Simulation sim(p, solver);
  const SimState s = run(sim, int(10 * p.tick_hz));
  const SheetStats st = computeStats(s, p.substepDt());
  float depth = 0.0f; // how far the wind bent it out of its plane
  for (const glm::vec4& q : s.pos) depth = std::max(depth, std::abs(q.z));
  std::printf("wind: %.2f out of its plane, largest rest angle %.3f deg, %u creased\n", double(depth),
              double(st.max_crease_deg), st.creased);
  EXPECT_GT(s.hinges.size(), 0u);
  EXPECT_GT(depth, 0.3f);
  EXPECT_LE(st.max_crease_deg, 2.0f);
}

TEST(Crease, EveryCreaseComesFromWhereTheSheetWent) {
  TENDER_ONE_THREAD_TEST();
  // The return map's promise, checked on the positions the sheet ends every fifth tick at: no live
  // hinge is bent further than its yield from its rest angle. The hand crumples a sheet with contact,
  // whose cut takes back steps that the projection made; a crease made from such a step (the return
  // map before the cut) leaves the rest angle where the sheet never went.
  const SimParams p = flatSheet(crumpleSheet(), {"cols=20", "rows=30"});
  CpuSolver solver;
  Simulation sim(p, solver);
  const SimState flat = run(sim, 0);
  auto [text, ticks] = crumpleScript(p, glm::vec3(flat.pos[(p.rows / 2) * p.cols + p.cols / 2]));
  sim.setScript(script(text.c_str()));
  const float yield0 = float(double(p.crease_yield) / kDeg);
  double worst = 0.0; // the most any hinge is past its yield at the end of a tick (radians)
  uint32_t creased = 0;
  for (int t = 0; t < ticks; t += 5) {
    const SimState s = run(sim, 5);
    for (uint32_t k = 0; k < s.hinges.size(); ++k) {
      const glm::uvec4 q = gridHinge(k, p.cols, p.rows);
      const HingeAngle h =
          hingeAngle(glm::vec3(s.pos[q.x]), glm::vec3(s.pos[q.y]), glm::vec3(s.pos[q.z]), glm::vec3(s.pos[q.w]), false);
      if (!h.valid || s.torn[s.torn.size() - s.hinges.size() + k] != 0u) continue;
      const glm::vec4 st = s.hinges[k];
      worst = std::max(worst, double(std::abs(wrapAngle(h.angle - st.x)) - (yield0 + st.y)));
    }
    creased = computeStats(s, p.substepDt()).creased;
  }
  std::printf("crumple: %u hinges creased, the most past its yield %.2e rad\n", creased, worst);
  EXPECT_GT(creased, 50u);
  EXPECT_LE(worst, 1e-5);
}

} // namespace
} // namespace tender::test
