// A tick cut short after any pass (Solver::stopNextTickAfter, what `tender diff` bisects with)
// leaves the GPU solver, with the fused tick and with the per-colour passes, in bitwise the CPU
// reference's state, the collision deltas of a collide pass included.
#include <set>

#include "core/passes.h"
#include "core/stats.h"
#include "cpu/cpu_solver.h"
#include "gpu/gpu_solver.h"
#include "gpu_test_env.h"

using namespace tender;
using namespace tender::test;

namespace {

struct Cut {
  SimState state;
  std::vector<glm::vec4> deltas;
  PassPoint pass;
};

// Runs `ticks` whole ticks from the start, then one that stops after pass `stop`.
Cut runCut(Solver& solver, const SimParams& p, const char* text, uint64_t ticks, uint32_t stop) {
  Simulation sim(p, solver);
  sim.setScript(script(text));
  for (uint64_t t = 0; t < ticks; ++t) sim.tick();
  solver.stopNextTickAfter(stop);
  sim.tick();
  Cut c;
  solver.finish();
  solver.readback(c.state);
  solver.readDeltas(c.deltas);
  c.pass = passAt(sim.lastUniforms(), stop);
  return c;
}

class StoppedTick : public GpuTest {};

} // namespace

TEST_F(StoppedTick, EveryPassMatchesTheCpuFusedAndPerColour) {
  const SimParams p = cloth({"wind=off", "air=on", "substeps=2", "iterations=2", "stretch_limit=1.01"});
  const char* text = "0 grab particle 1535\n1 move 7 -4 6\n";
  // The tick in which the first constraints tear
  CpuSolver probe;
  Simulation sim(p, probe);
  sim.setScript(script(text));
  uint64_t tick = 0;
  for (SimState s; tick < 40; ++tick) {
    sim.tick();
    probe.readback(s);
    if (tornCount(s) > 0) break;
  }
  ASSERT_LT(tick, 40u) << "the yank tore nothing";
  const shaderio::SimUniforms u = sim.lastUniforms();
  const uint32_t passes = passesPerTick(u);
  ASSERT_EQ(passes, 2u * shaderio::passesPerSubstep(2, sim.topology().colorCount(), conditionsOf(u)));
  ASSERT_TRUE(shaderio::runsWhen(SIM_WHEN_COLLISION | SIM_WHEN_AIR, conditionsOf(u)));

  gpu::GpuSolver fused(ctx()), percolor(ctx());
  percolor.setFusedPath(false);
  CpuSolver cpu;
  std::set<uint64_t> distinct;
  bool deltas_compared = false;
  uint32_t torn_before_last = 0, torn_at_end = 0;
  for (uint32_t k = 0; k < passes; ++k) {
    const Cut ref = runCut(cpu, p, text, tick, k);
    ASSERT_EQ(ref.pass, passAt(u, k));
    distinct.insert(hashPositions(ref.state.pos));
    if (k + 2 == passes) torn_before_last = tornCount(ref.state);
    if (k + 1 == passes) torn_at_end = tornCount(ref.state);
    for (gpu::GpuSolver* g : {&fused, &percolor}) {
      const Cut got = runCut(*g, p, text, tick, k);
      const char* path = g == &fused ? "fused" : "per-colour";
      EXPECT_TRUE(sameState(ref.state, got.state)) << path << ", after pass " << k << ": " << describePass(ref.pass);
      if (ref.pass.kind == PassKind::collide) {
        EXPECT_TRUE(sameBytes(ref.deltas, got.deltas)) << path << ", deltas after " << describePass(ref.pass);
        for (const glm::vec4& d : ref.deltas) deltas_compared = deltas_compared || d != glm::vec4(0.0f);
      }
    }
  }
  EXPECT_TRUE(fused.usesFusedPath());
  EXPECT_FALSE(percolor.usesFusedPath());
  // The cuts really stop: positions change from pass to pass (in each substep the air, which
  // writes what the integration reads, the floor, with nothing below it, and the tear move none;
  // the collide moves what it repels), and the collide passes had repulsion to compare. The stages
  // whose conditions fail have no passes: the crease (no hinges), the settle and contact's (no
  // contact), the shorten stage (the sheet is held).
  for (uint32_t k = 0; k < passes; ++k)
    for (PassKind none : {PassKind::contact, PassKind::shorten, PassKind::crease, PassKind::settle})
      EXPECT_NE(passAt(u, k).kind, none) << describePass(passAt(u, k));
  EXPECT_GE(distinct.size(), size_t(passes) - 6u);
  EXPECT_GT(torn_at_end, torn_before_last);
  EXPECT_TRUE(deltas_compared) << "no collide pass of the tick had a repulsion";
}

// The shorten stage, which runs while nothing holds the sheet: a pinless sheet yanked and let go,
// cut after each pass of the shorten stage (and the projection's last before it) in the tick after
// the release, gives the CPU's bits on both GPU paths, and the stage moves the sheet.
TEST_F(StoppedTick, EveryShortenPassMatchesTheCpuFusedAndPerColour) {
  const SimParams p = cloth({"cols=16", "rows=24", "wind=off", "pins=none", "substeps=2", "iterations=2",
                             "stretch_limit=1.01", "tear_factor=0"});
  const char* text = "0 grab particle 383\n1 move 7 -4 6\n6 release\n";
  const uint64_t tick = 7;
  CpuSolver probe;
  Simulation sim(p, probe);
  sim.setScript(script(text));
  for (uint64_t t = 0; t <= tick; ++t) sim.tick();
  const shaderio::SimUniforms u = sim.lastUniforms();
  ASSERT_EQ(u.grab_index, SIM_NONE);
  ASSERT_TRUE(shaderio::limitShortens(u.limit.reach, u.grab_index, u.flags));
  gpu::GpuSolver fused(ctx()), percolor(ctx());
  percolor.setFusedPath(false);
  CpuSolver cpu;
  uint32_t cuts = 0, moved = 0;
  uint64_t last = 0;
  for (uint32_t k = 0; k < passesPerTick(u); ++k) {
    const PassPoint at = passAt(u, k), next = passAt(u, k + 1 < passesPerTick(u) ? k + 1 : k);
    if (at.kind != PassKind::shorten && next.kind != PassKind::shorten) continue;
    const Cut ref = runCut(cpu, p, text, tick, k);
    const uint64_t hash = hashPositions(ref.state.pos);
    if (at.kind == PassKind::shorten) {
      ++cuts;
      moved += hash != last;
    }
    last = hash;
    for (gpu::GpuSolver* g : {&fused, &percolor}) {
      const Cut got = runCut(*g, p, text, tick, k);
      EXPECT_TRUE(sameState(ref.state, got.state))
          << (g == &fused ? "fused" : "per-colour") << ", after pass " << k << ": " << describePass(ref.pass);
    }
  }
  EXPECT_TRUE(fused.usesFusedPath());
  EXPECT_EQ(cuts, 2u * 2u * sim.topology().colorCount());
  EXPECT_GE(moved, cuts / 4) << "the shorten stage moved the sheet in " << moved << " of its " << cuts << " passes";
}
