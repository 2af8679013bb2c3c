// The behaviour every solver shares (tests/common/solver_cases.h) on both GPU paths: the fused
// small-sheet tick and the per-colour passes, built as every program builds them; the fused
// tick's count of its barriers; and the kernels timed apart.
#include <map>

#include "backend/backend.h"
#include "common/solver_cases.h"
#include "gpu/gpu_solver.h"
#include "gpu_test_env.h"

using namespace tender;
using namespace tender::test;

namespace {

template <const char* kBackend>
struct GpuBackend {
  static constexpr const char* kName = kBackend;
  using Fixture = GpuTest;
  static std::unique_ptr<Solver> make(GpuTest& f) {
    BackendOptions o;
    o.backend = kBackend;
    o.context = &f.ctx();
    Backend b;
    auto err = createBackend(o, b);
    EXPECT_FALSE(err) << *err;
    return std::move(b.solver);
  }
};

constexpr char kFused[] = "gpu", kPerColor[] = "gpu-percolor";

} // namespace

namespace tender::test {
using GpuBackends = ::testing::Types<GpuBackend<kFused>, GpuBackend<kPerColor>>;
INSTANTIATE_TYPED_TEST_SUITE_P(Gpu, SolverCase, GpuBackends, BackendName);
} // namespace tender::test

TEST_F(GpuTest, TheFusedTickCountsABarrierForEachColourOfEachIteration) {
  // Counters::phases, what tender-bench prints as a tick's phases: an iteration more adds a barrier
  // for each colour of each substep (the first tick from rest, the same in both but for the
  // iterations), and the per-colour passes, whose dispatches take the barriers' place, count none
  auto phases = [&](std::initializer_list<const char*> sets, bool fused) {
    SimParams p = cloth({"cols=12", "rows=16", "wind=off"}); // SimParams{}: no contact, so it may run fused
    p = withSets(p, std::vector<std::string>(sets.begin(), sets.end()));
    gpu::GpuSolver solver(ctx());
    solver.setFusedPath(fused);
    Simulation sim(p, solver);
    sim.tick();
    return std::pair(solver.barrierPhasesPerTick(), sim.topology().colorCount());
  };
  const auto [four, colours] = phases({"iterations=4", "substeps=2"}, true);
  const auto [five, unused] = phases({"iterations=5", "substeps=2"}, true);
  std::printf("fused tick of 2 substeps: %u barriers at 4 iterations, %u at 5 (%u colours)\n", four, five, colours);
  EXPECT_GT(four, 2u * 4u * colours);
  EXPECT_EQ(five - four, 2u * colours);
  EXPECT_EQ(phases({"iterations=4", "substeps=2"}, false).first, 0u);
}

TEST_F(GpuTest, KernelsTimedApartAddUpToTheirPassesAndChangeNoBit) {
  // timeKernels (`tender sim --kernel-times`): a timestamp after every dispatch of the per-colour
  // passes names each kernel that ran with its time, which its passes' times hold, and the bits
  // stay the CPU's; turned off, the kernels go unnamed again
  const SimParams p = clothWithContact({"cols=8", "rows=12", "wind=off"});
  CpuSolver cpu;
  Simulation a(p, cpu);
  const SimState cpu_end = run(a, 3);
  gpu::GpuSolver gpu(ctx());
  gpu.setFusedPath(false);
  gpu.timeKernels(true);
  Simulation g(p, gpu);
  EXPECT_TRUE(sameState(cpu_end, run(g, 3)));
  const PassTimes t = gpu.passTimes();
  const std::map<std::string, double> kernels(t.kernels.begin(), t.kernels.end());
  double in_kernels = 0.0, in_passes = 0.0;
  for (const auto& [name, ms] : t.kernels) in_kernels += ms;
  for (const auto& [name, ms] : t.ms) in_passes += name == "normals" ? 0.0 : ms;
  std::printf("%zu kernels: %.3f ms of the passes' %.3f\n", kernels.size(), in_kernels, in_passes);
  for (const char* name : {"integrate", "project", "contact_near", "contact_step"})
    EXPECT_EQ(kernels.count(name), 1u) << name;
  EXPECT_GT(in_kernels, 0.0);
  EXPECT_LE(in_kernels, in_passes * (1.0 + 1e-9));
  gpu.timeKernels(false);
  g.tick();
  EXPECT_TRUE(gpu.passTimes().kernels.empty());
}
