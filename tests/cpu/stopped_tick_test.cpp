// A tick cut short (Solver::stopNextTickAfter) runs exactly the passes up to the stop, in the
// order of passes.h; the planted ULP of `tender diff`'s test hook changes one coordinate by one
// ULP after one pass.
#include <cmath>

#include "common/sim_helpers.h"
#include "core/passes.h"
#include "cpu/cpu_solver.h"

using namespace tender;
using namespace tender::test;

namespace {

const char* kYank = "0 grab particle 300\n1 move 3 -2 4\n";

SimParams sheet() { return cloth({"cols=16", "rows=24", "substeps=2", "iterations=2", "wind=on"}); }

} // namespace

TEST(StoppedTick, RunsThePassesUpToTheStopInOrder) {
  const SimParams p = sheet();
  for (uint32_t stop : {0u, 1u, 2u, 5u}) {
    // Reference: the same tick driven pass by pass
    CpuSolver a, b;
    Simulation sa(p, a), sb(p, b);
    sa.setScript(script(kYank));
    sb.setScript(script(kYank));
    for (int t = 0; t < 3; ++t) sa.tick(), sb.tick();
    const shaderio::SimUniforms u = sa.makeUniforms();
    a.stopNextTickAfter(stop);
    a.tick(u);
    ASSERT_EQ(passAt(u, 0).kind, PassKind::integrate);
    b.integrate(u, 0, shaderio::runsWhen(SIM_WHEN_AIR, conditionsOf(u)));
    if (stop > 0) b.collide(u), b.repelPass(u);
    if (stop > 1) b.projectColors(u, 0, stop - 1);
    EXPECT_TRUE(sameBytes(a.positions(), b.positions())) << "stop after pass " << stop;
    EXPECT_TRUE(sameBytes(a.previous(), b.previous())) << "stop after pass " << stop;
    // The stop holds for one tick: the next runs whole, as on a solver never stopped.
  }
}

TEST(StoppedTick, AStopAtTheLastPassIsTheWholeTick) {
  const SimParams p = sheet();
  CpuSolver a, b;
  Simulation sa(p, a), sb(p, b);
  sa.setScript(script(kYank));
  sb.setScript(script(kYank));
  for (int t = 0; t < 4; ++t) {
    sa.tick();
    b.stopNextTickAfter(passesPerTick(sa.lastUniforms()) - 1);
    sb.tick();
  }
  EXPECT_TRUE(sameBytes(a.positions(), b.positions()));
  // A stop before the end changes the result
  b.stopNextTickAfter(3);
  sb.tick();
  sa.tick();
  EXPECT_FALSE(sameBytes(a.positions(), b.positions()));
}

TEST(StoppedTick, PlantedUlpMovesOneCoordinateAfterItsPass) {
  const SimParams p = sheet();
  std::string error;
  auto plant = parsePlantedUlp("2:1:project.1.3:77", error);
  ASSERT_TRUE(plant) << error;
  CpuSolver a, b;
  b.setPlantedUlp(plant);
  Simulation sa(p, a), sb(p, b);
  sa.setScript(script(kYank));
  sb.setScript(script(kYank));
  for (int t = 0; t < 2; ++t) sa.tick(), sb.tick();
  EXPECT_TRUE(sameBytes(a.positions(), b.positions())) << "planted too early";
  // Stop both right after the planted pass: exactly one coordinate is one ULP up
  const uint32_t at = *passIndex(sa.makeUniforms(), plant->pass);
  a.stopNextTickAfter(at);
  b.stopNextTickAfter(at);
  sa.tick();
  sb.tick();
  for (uint32_t i = 0; i < a.positions().size(); ++i) {
    const glm::vec4 x = a.positions()[i], y = b.positions()[i];
    if (i == 77) {
      EXPECT_EQ(y.x, std::nextafter(x.x, INFINITY));
      EXPECT_EQ(glm::vec3(y.y, y.z, y.w), glm::vec3(x.y, x.z, x.w));
    } else {
      ASSERT_EQ(x, y) << "particle " << i;
    }
  }
}
