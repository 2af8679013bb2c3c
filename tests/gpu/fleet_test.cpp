// A fleet on the GPU: one dispatch ticks every sheet, and each sheet ends bitwise where the same
// sheet ends run alone on the GPU solver (fused or per-colour: they agree).
#include <algorithm>
#include <thread>

#include "common/fleet_cases.h"
#include "gpu/gpu_fleet.h"
#include "gpu/gpu_solver.h"
#include "gpu_test_env.h"

namespace tender::test {
namespace {

class GpuFleetTest : public GpuTest {};

TEST_F(GpuFleetTest, EachSheetOfAMixedBatchMatchesItsRunAlone) {
  const std::vector<FleetSheet> sheets = mixedFleet(37);
  gpu::GpuFleet batch(ctx(), uint32_t(sheets.size()));
  gpu::GpuSolver alone(ctx());
  const uint32_t tore = expectFleetMatchesAlone(batch, alone, sheets, 60);
  EXPECT_GT(tore, 0u);
  EXPECT_LT(tore, sheets.size());
}

TEST_F(GpuFleetTest, TheFleetMatchesTheCpuReference) {
  const std::vector<FleetSheet> sheets = mixedFleet(9);
  gpu::GpuFleet batch(ctx(), uint32_t(sheets.size()));
  CpuSolver alone(cpuOptionsLike(ctx()));
  expectFleetMatchesAlone(batch, alone, sheets, 40);
}

TEST_F(GpuFleetTest, OneDispatchRunsEveryQueuedSheetsTick) {
  const std::vector<FleetSheet> sheets = mixedFleet(4);
  gpu::GpuFleet batch(ctx(), 4);
  Fleet fleet(batch, sheets);
  fleet.tick();
  for (uint32_t i = 0; i < 4; ++i) EXPECT_EQ(fleet.sim(i).physicsTicks(), 1u);
  // Sheets of 6, 7 and 8 substeps. A GPU runs every sheet's whole tick in one dispatch; a CPU
  // device runs a substep per dispatch (8), a group of SIM_BATCH_CPU_SHEETS_PER_THREAD sheets per
  // hardware thread at a time.
  const bool cpu_device = ctx().properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
  const uint32_t group = std::max(1u, std::thread::hardware_concurrency()) * SIM_BATCH_CPU_SHEETS_PER_THREAD;
  EXPECT_EQ(batch.dispatchesPerFlush(), cpu_device ? (4 + group - 1) / group * 8 : 1u);
}

TEST_F(GpuFleetTest, LargeSheetsAndLargeCellsAreRefused) {
  SimParams p = preset("tender");
  EXPECT_FALSE(gpu::GpuFleet::fits(p));
  p.cols = 64;
  p.rows = 64;
  EXPECT_TRUE(gpu::GpuFleet::fits(p));
  p = preset("tender", {"cell_size=2"});
  EXPECT_TRUE(gpu::GpuFleet::fits(p));
}

} // namespace
} // namespace tender::test
