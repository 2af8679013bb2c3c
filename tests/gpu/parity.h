#pragma once
/// The parity tests' fixture and helpers: the same parameters and script on the CPU reference and
/// the GPU solver, and the topology they leave.
#include <set>
#include <utility>

#include "cpu/cpu_solver.h"
#include "gpu/gpu_solver.h"
#include "gpu_test_env.h"

namespace tender::test {

/// The fused tick's invocations where a test takes a GPU's shape on lavapipe: fewer than a GPU's
/// SIM_WG_FUSED, as lavapipe takes turns over every 8 of them at each barrier; any size gives the
/// same bits (Parity.FusedTickOfAnyWorkgroupSize).
inline constexpr uint32_t kGpuLikeWorkgroup = 256;

class Parity : public GpuTest {
protected:
  /// Runs p on the GPU (the fused tick, or the per-colour passes) and the CPU, checking the
  /// candidate lists whenever usable.
  void checkCandidateLists(const SimParams& p, bool fused, bool expect_entries);
};

/// The fused tick with contact's bodies in its workgroup, as a GPU runs it (a CPU device's own shape
/// runs sheets with contact on the per-colour passes); the rest of the shape the device's.
inline constexpr gpu::FusedShape kContactInTheWorkgroup{0, 0, 0.0f, 1};

/// Runs the same parameters and script on both solvers; returns {cpu, gpu} states. `fused`
/// allows the GPU's fused small-sheet tick (used when the sheet fits), in the given shape.
inline std::pair<SimState, SimState> runBoth(gpu::VulkanContext& ctx, const SimParams& p, const char* text, int ticks,
                                             bool fused = true, gpu::FusedShape shape = kContactInTheWorkgroup) {
  gpu::GpuSolver gpu(ctx, shape);
  CpuSolver cpu;
  gpu.setFusedPath(fused);
  Simulation a(p, cpu), b(p, gpu);
  a.setScript(script(text));
  b.setScript(script(text));
  return {run(a, ticks), run(b, ticks)};
}

inline std::set<uint32_t> tornIds(const SimState& s) {
  std::set<uint32_t> ids;
  for (uint32_t k = 0; k < s.torn.size(); ++k)
    if (s.torn[k]) ids.insert(k);
  return ids;
}

/// Same topology after tearing: torn ids, colour counts, triangle lists.
inline void expectSameTopology(const SimState& cpu, const SimState& gpu) {
  EXPECT_EQ(tornIds(cpu), tornIds(gpu));
  ASSERT_EQ(cpu.colors.size(), gpu.colors.size());
  for (size_t c = 0; c < cpu.colors.size(); ++c) {
    EXPECT_EQ(cpu.colors[c].first, gpu.colors[c].first);
    ASSERT_EQ(cpu.colors[c].count, gpu.colors[c].count) << "colour " << c;
    for (uint32_t k = cpu.colors[c].first; k < cpu.colors[c].first + cpu.colors[c].count; ++k)
      EXPECT_EQ(cpu.constraints[k].kind_id, gpu.constraints[k].kind_id) << "slot " << k;
  }
  EXPECT_EQ(cpu.triangle_count, gpu.triangle_count);
  EXPECT_EQ(cpu.triangles, gpu.triangles);
}

} // namespace tender::test
