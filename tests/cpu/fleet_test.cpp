// A fleet on the CPU: every sheet of a batch ends bitwise where it ends run alone.
#include "common/fleet_cases.h"
#include "cpu/cpu_batch.h"

namespace tender::test {
namespace {

TEST(CpuFleet, EachSheetOfAMixedBatchMatchesItsRunAlone) {
  const std::vector<FleetSheet> sheets = mixedFleet(37);
  CpuBatch batch(uint32_t(sheets.size()), 2);
  if (!kComparesThreadCounts) {
    // ThreadSanitizer judges the batch's jobs on its two threads; the ci and ASan builds compare the
    // bits with each sheet's run alone
    Fleet fleet(batch, sheets);
    for (int t = 0; t < 60; ++t) fleet.tick();
    return;
  }
  CpuSolver alone;
  const uint32_t tore = expectFleetMatchesAlone(batch, alone, sheets, 60);
  // Some sheets tore and some did not: the batch holds both.
  EXPECT_GT(tore, 0u);
  EXPECT_LT(tore, sheets.size());
}

TEST(CpuFleet, ABatchRunsEachSheetsTickOnceAsOneJob) {
  const std::vector<FleetSheet> sheets = mixedFleet(5);
  CpuBatch batch(5, 2);
  Fleet fleet(batch, sheets);
  fleet.tick();
  EXPECT_EQ(batch.dispatchesPerFlush(), 5u);
  for (uint32_t i = 0; i < 5; ++i) EXPECT_EQ(fleet.sim(i).physicsTicks(), 1u);
}

TEST(CpuFleet, SheetsOfDifferentGridsCannotShareABatch) {
  std::vector<FleetSheet> sheets = mixedFleet(2);
  sheets[1].params.cols = 13;
  CpuBatch batch(2, 1);
  EXPECT_THROW(Fleet(batch, sheets), std::invalid_argument);
  EXPECT_TRUE(batchMismatch(sheets[0].params, sheets[1].params));
  EXPECT_FALSE(batchMismatch(sheets[0].params, sheets[0].params));
}

} // namespace
} // namespace tender::test
