#pragma once
/// Whole runs of the CPU solver and bitwise comparisons of their states, for the CPU tests.
#include <string>
#include <vector>

#include "common/sim_helpers.h"
#include "cpu/cpu_solver.h"

namespace tender::test {

/// Runs `ticks` ticks of a sheet (with a script) and returns the final state.
inline SimState runCpu(const SimParams& p, const std::string& script_text, int ticks, CpuOptions options) {
  CpuSolver solver(options);
  Simulation sim(p, solver);
  if (!script_text.empty()) sim.setScript(script(script_text.c_str()));
  return run(sim, ticks);
}
/// The same of a preset with overrides.
inline SimState runCpu(const std::string& preset_name, const std::vector<std::string>& sets,
                       const std::string& script_text, int ticks, CpuOptions options) {
  return runCpu(preset(preset_name, sets), script_text, ticks, options);
}

/// Expects two states to be bitwise identical, array by array.
inline void expectIdentical(const SimState& a, const SimState& b) {
  // Two empty read-backs are no evidence of equal runs (triangles and torn flags may be empty).
  EXPECT_FALSE(a.pos.empty() || a.prev.empty() || a.constraints.empty()) << "an empty read-back";
  EXPECT_TRUE(sameBytes(a.pos, b.pos));
  EXPECT_TRUE(sameBytes(a.prev, b.prev));
  EXPECT_TRUE(sameBytes(a.normal, b.normal));
  EXPECT_TRUE(sameBytes(a.constraints, b.constraints));
  EXPECT_TRUE(sameBytes(a.colors, b.colors));
  EXPECT_TRUE(sameBytes(a.torn, b.torn));
  EXPECT_TRUE(sameBytes(a.hinges, b.hinges));
  EXPECT_TRUE(sameBytes(a.triangles, b.triangles));
  EXPECT_EQ(a.triangle_count, b.triangle_count);
}

} // namespace tender::test
