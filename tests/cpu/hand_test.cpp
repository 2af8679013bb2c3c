// The hand: a sheet crumpled by a dozen grabs towards its middle keeps its size and its folds once
// let go (radius of gyration, hinge angles).
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

/// The radius of gyration of the particles about their centre.
double gyration(const SimState& s) {
  glm::dvec3 c(0.0);
  for (const glm::vec4& q : s.pos) c += glm::dvec3(q);
  c /= double(s.pos.size());
  double sum = 0.0;
  for (const glm::vec4& q : s.pos) sum += glm::dot(glm::dvec3(q) - c, glm::dvec3(q) - c);
  return std::sqrt(sum / double(s.pos.size()));
}

/// The 95th percentile of the hinges' |angle| (degrees).
double hingeP95(const SimState& s, const SimParams& p) {
  std::vector<double> a;
  for (uint32_t k = 0; k < s.hinges.size(); ++k) {
    const glm::uvec4 q = gridHinge(k, p.cols, p.rows);
    const HingeAngle g =
        hingeAngle(glm::vec3(s.pos[q.x]), glm::vec3(s.pos[q.y]), glm::vec3(s.pos[q.z]), glm::vec3(s.pos[q.w]), false);
    a.push_back(g.valid ? std::abs(double(g.angle)) * kDeg : 0.0);
  }
  std::nth_element(a.begin(), a.begin() + a.size() * 95 / 100, a.end());
  return a[a.size() * 95 / 100];
}

TEST(Hand, ACrumpledBallKeepsItsSizeAndItsFolds) {
  TENDER_ONE_THREAD_TEST();
  // Crumpled by the hand and let go on the floor, the ball springs back a little as the hand lets
  // go of its layers (the first second), then keeps its size and its folds for five seconds.
  const SimParams p = flatSheet("crumple", {"cols=20", "rows=30"});
  CpuSolver solver;
  Simulation sim(p, solver);
  const SimState flat = run(sim, 0);
  auto [text, ticks] = crumpleScript(p, glm::vec3(flat.pos[(p.rows / 2) * p.cols + p.cols / 2]));
  sim.setScript(script(text.c_str()));
  const SimState held = run(sim, ticks - 2); // the last tick the hand holds
  EXPECT_GT(sim.closure(), 0.99f);
  const SimState settled = run(sim, 2 + int(p.tick_hz));
  const SimState later = run(sim, int(5 * p.tick_hz));
  EXPECT_EQ(sim.closure(), 0.0f); // letting go opens the hand
  const double r_flat = gyration(flat), r_held = gyration(held), r0 = gyration(settled), r5 = gyration(later);
  const double p0 = hingeP95(settled, p), p5 = hingeP95(later, p);
  std::printf("hand: radius of gyration flat %.3f, in the hand %.3f, let go %.3f, 5 s later %.3f; 95th percentile "
              "hinge angle %.1f -> %.1f deg\n",
              r_flat, r_held, r0, r5, p0, p5);
  EXPECT_EQ(computeStats(later, p.substepDt()).nan_count, 0u);
  // A ball, not a sheet: the fist of a closed hand holds the sheet's area, in layers a collision
  // radius thick, at a packing of a quarter (kHandPacking): a radius of gyration of about 0.63 x the
  // flat sheet's here
  EXPECT_LT(r_held, 0.65 * r_flat);
  EXPECT_LT(r0, 0.8 * r_flat);
  EXPECT_NEAR(r5, r0, 0.03 * r0);
  EXPECT_GT(p0, 25.0); // folded through
  EXPECT_NEAR(p5, p0, 0.1 * p0);
}

} // namespace
} // namespace tender::test
