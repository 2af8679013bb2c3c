// The `paper` preset and the air on each triangle: a receipt let go in still air falls, glides and
// lands like paper; a flat sheet reaches the terminal speed of quadratic drag.
#include <gtest/gtest.h>

#include <cmath>

#include "common/sim_helpers.h"
#include "cpu/cpu_solver.h"

namespace tender::test {
namespace {

struct Extent {
  float ymin = 0.0f, ymax = 0.0f;
  glm::vec3 centre{0.0f}, velocity{0.0f};
};

Extent extentOf(Solver& solver, float dt) {
  SimState s;
  solver.readback(s);
  Extent e{s.pos[0].y, s.pos[0].y};
  for (size_t i = 0; i < s.pos.size(); ++i) {
    e.ymin = std::min(e.ymin, s.pos[i].y);
    e.ymax = std::max(e.ymax, s.pos[i].y);
    e.centre += glm::vec3(s.pos[i]);
    e.velocity += (glm::vec3(s.pos[i]) - glm::vec3(s.prev[i])) / dt;
  }
  e.centre /= float(s.pos.size());
  e.velocity /= float(s.pos.size());
  return e;
}

TEST(Paper, AReceiptLetGoOneMetreUpGlidesAndLandsNearlyFlat) {
  TENDER_ONE_THREAD_TEST();
  const SimParams p = receiptWithContact();
  CpuSolver solver;
  Simulation sim(p, solver);
  const Extent start = extentOf(solver, p.substepDt());
  EXPECT_NEAR(start.ymin - p.floor_y, 1.0f, 1e-4f); // its lowest point 1 m above the floor
  EXPECT_NEAR(float(p.cols - 1) * p.spacing, 0.08f, 1e-5f);
  EXPECT_NEAR(float(p.rows - 1) * p.spacing, 0.30f, 1e-5f);
  double landed = -1.0;
  Extent at_landing;
  float most_pitch = 0.0f;
  for (int t = 1; t <= int(3.5f * p.tick_hz) && landed < 0.0; ++t) {
    sim.tick();
    const Extent e = extentOf(solver, p.substepDt());
    most_pitch = std::max(most_pitch, e.ymax - e.ymin);
    if (e.ymin <= p.floor_y + 0.002f) {
      landed = double(t) / p.tick_hz;
      at_landing = e;
    }
  }
  std::printf("paper: landed after %.3f s (free fall: 0.45 s), %.3f m apart in height, %.3f m away\n", landed,
              at_landing.ymax - at_landing.ymin, glm::length(glm::vec2(at_landing.centre.x, at_landing.centre.z)));
  EXPECT_GE(landed, 1.0);
  EXPECT_LE(landed, 3.0);
  // It glides away from under its start, and lands still pitched (a corner or an edge first)
  EXPECT_GT(at_landing.ymax - at_landing.ymin, 0.01f);
  EXPECT_GT(
      glm::length(glm::vec2(at_landing.centre.x, at_landing.centre.z) - glm::vec2(start.centre.x, start.centre.z)),
      0.1f);
  // A second later it lies on the floor nearly flat, not folded over: paper's bending rigidity
  for (int t = 0; t < int(p.tick_hz); ++t) sim.tick();
  SimState s;
  solver.readback(s);
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  for (const glm::vec4& q : s.pos) lo = glm::min(lo, glm::vec3(q)), hi = glm::max(hi, glm::vec3(q));
  const glm::vec3 size = hi - lo;
  std::printf("paper: settled %.3f x %.3f m, %.4f m high\n", std::max(size.x, size.z), std::min(size.x, size.z),
              size.y);
  EXPECT_GT(std::max(size.x, size.z), 0.27f);
  EXPECT_LT(size.y, 0.02f);
}

TEST(Paper, AFlatSheetFallsAtTheTerminalSpeedOfQuadraticDrag) {
  TENDER_ONE_THREAD_TEST();
  // Flat and level, it falls straight down; drag rho C v^2 / 2 per area balances its weight
  // sigma g at v = sqrt(2 sigma g / (rho C)).
  const SimParams p = receiptWithContact({"tilt=90", "floor_y=-100", "collision=off", "skin_friction=0"});
  CpuSolver solver;
  Simulation sim(p, solver);
  for (int t = 0; t < int(2.0f * p.tick_hz); ++t) sim.tick();
  const Extent e = extentOf(solver, p.substepDt());
  const float terminal = std::sqrt(2.0f * p.paper_weight * 1e-3f * p.gravity / (p.air_density * p.drag_coefficient));
  std::printf("flat sheet: %.4f m/s after 2 s, terminal %.4f m/s\n", -e.velocity.y, terminal);
  EXPECT_NEAR(-e.velocity.y, terminal, 0.01f * terminal);
  EXPECT_NEAR(e.velocity.x, 0.0f, 1e-4f);
  EXPECT_NEAR(e.velocity.z, 0.0f, 1e-4f);
  EXPECT_LT(e.ymax - e.ymin, 1e-3f); // still level
}

TEST(Paper, WithoutAirTheSheetFallsFreely) {
  const SimParams p = receiptWithContact({"air=off", "tilt=90", "floor_y=-100", "collision=off"});
  CpuSolver solver;
  Simulation sim(p, solver);
  const int ticks = int(0.5f * p.tick_hz);
  for (int t = 0; t < ticks; ++t) sim.tick();
  const Extent e = extentOf(solver, p.substepDt());
  // Verlet without damping: v = g t at the substep before the last, to a substep's g dt.
  EXPECT_NEAR(-e.velocity.y, p.gravity * 0.5f, p.gravity * p.substepDt() * 1.01f);
}

} // namespace
} // namespace tender::test
