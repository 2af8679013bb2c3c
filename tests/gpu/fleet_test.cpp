// A fleet on the GPU: one dispatch ticks every sheet the fused tick takes, one dispatch per pass
// the others, and each sheet ends bitwise where the same sheet ends run alone on the GPU solver.
#include <algorithm>
#include <string>
#include <thread>

#include "common/fleet_cases.h"
#include "gpu/gpu_batch.h"
#include "gpu/gpu_solver.h"
#include "gpu_test_env.h"

namespace tender::test {
namespace {

class GpuBatchTest : public GpuTest {};

// Each fleet below is compared with its sheets run alone on the CPU reference: the GPU solver
// gives a sheet alone the same bits (the Parity tests), and the CPU runs it in a fraction of the
// time a CPU device takes.

TEST_F(GpuBatchTest, EachSheetOfAMixedBatchMatchesTheCpuReference) {
  // Thirteen sheets: every script, pinning, wind, tear factor, substep and iteration count of
  // mixedFleet, in more groups than a CPU device dispatches at once (one a hardware thread)
  const std::vector<FleetSheet> sheets = mixedFleet(13);
  gpu::GpuBatch batch(ctx(), uint32_t(sheets.size()));
  CpuSolver alone;
  const uint32_t tore = expectFleetMatchesAlone(batch, alone, sheets, 60);
  EXPECT_GT(tore, 0u);
  EXPECT_LT(tore, sheets.size());
}

TEST_F(GpuBatchTest, SheetsOfPaperMatchTheCpuReference) {
  // Hinges, creases, the stretch limit and the hand in a fleet, and the receipt in the air: every
  // value the shaders read of a fleet's uniforms, by device address, is the sheet's own. The paper
  // to its scripts' last release (tick 15) and after; the receipts past theirs (tick 10).
  for (bool receipt : {false, true}) {
    const std::vector<FleetSheet> sheets = paperFleet(receipt ? 4 : 12, receipt);
    gpu::GpuBatch batch(ctx(), uint32_t(sheets.size()));
    CpuSolver alone;
    expectFleetMatchesAlone(batch, alone, sheets, receipt ? 12 : 18);
  }
}

TEST_F(GpuBatchTest, AFusedTickOfAnyWorkgroupSizeMatchesTheCpuReference) {
  // The fleet's fused tick with the largest workgroup it can be asked for (tender-bench
  // --fused-workgroup): each sheet's scans meet in SIM_WG_FUSED_MAX slots of its own.
  const std::vector<FleetSheet> sheets = mixedFleet(3);
  gpu::FusedShape shape;
  shape.workgroup = SIM_WG_FUSED_MAX;
  {
    // every sheet in the fused tick: one dispatch a tick on a GPU; on a CPU device one a substep
    // for each group of sheets (OneDispatchRunsEveryQueuedSheetsTick)
    gpu::GpuBatch batch(ctx(), uint32_t(sheets.size()), gpu::BatchPasses::Auto, shape);
    Fleet fleet(batch, sheets);
    fleet.tick();
    const bool cpu_device = ctx().properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    const uint32_t group = std::max(1u, std::thread::hardware_concurrency()) * SIM_BATCH_CPU_SHEETS_PER_THREAD;
    EXPECT_EQ(batch.dispatchesPerFlush(), cpu_device ? (3 + group - 1) / group * 8 : 1u);
  }
  gpu::GpuBatch batch(ctx(), uint32_t(sheets.size()), gpu::BatchPasses::Auto, shape);
  CpuSolver alone;
  EXPECT_GT(expectFleetMatchesAlone(batch, alone, sheets, 20), 0u);
}

TEST_F(GpuBatchTest, OneDispatchRunsEveryQueuedSheetsTick) {
  const std::vector<FleetSheet> sheets = mixedFleet(4);
  gpu::GpuBatch batch(ctx(), 4);
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

/// `sheets` with contact on in every other sheet from the second (the first has none, so the fleet
/// sizes its contact buffers when the second is made), from the fourth with the stretch limit and
/// the settle's sweeps.
std::vector<FleetSheet> withContact(std::vector<FleetSheet> sheets) {
  for (size_t i = 1; i < sheets.size(); i += 2) {
    sheets[i].params.contact_factor = 0.5f;
    if (i < 3) continue;
    sheets[i].params.stretch_limit = 1.01f;
    sheets[i].params.contact_settle = 3;
  }
  return sheets;
}

TEST_F(GpuBatchTest, ContactSheetsMatchTheCpuReference) {
  // Sheets 1 and 3 with contact, whose bodies run in the fleet's fused tick as a GPU runs it: one
  // dispatch of tick_batch for the sheets without contact, one of tick_batch_contact for those
  // with (a CPU device: one each a substep and group of sheets). 12 ticks: both in contact
  // throughout, the yank's from tick 1 and the hand's from tick 4.
  const std::vector<FleetSheet> sheets = withContact(mixedFleet(4));
  gpu::FusedShape in_workgroup;
  in_workgroup.contact = 1;
  gpu::GpuBatch batch(ctx(), uint32_t(sheets.size()), gpu::BatchPasses::Auto, in_workgroup);
  {
    Fleet fleet(batch, sheets);
    fleet.tick();
    const bool cpu_device = ctx().properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    const uint32_t group = std::max(1u, std::thread::hardware_concurrency()) * SIM_BATCH_CPU_SHEETS_PER_THREAD;
    EXPECT_EQ(batch.dispatchesPerFlush(), cpu_device ? 2 * ((2 + group - 1) / group) * 8 : 2u);
  }
  CpuSolver alone;
  expectFleetMatchesAlone(batch, alone, sheets, 12);
  EXPECT_GT(alone.contacts(), 0); // the last sheet, alone: held in the closed hand, in contact
}

// The per-colour passes of sheets the fused tick does not take, both ways: batched (a GPU's
// default) and sheet by sheet (a CPU device's)
class GpuBatchPasses : public GpuTest, public testing::WithParamInterface<gpu::BatchPasses> {
protected:
  /// At least `rows` rows, and enough that a sheet of `cols` columns is too large for this device's
  /// fused tick (lavapipe holds 2,048 particles, NVIDIA's 48 KiB 3,072: fusedCapacity)
  uint32_t rowsPastTheFusedTick(uint32_t cols, uint32_t rows) {
    return std::max(rows, gpu::fusedCapacity(ctx()) / cols + 1);
  }
};

TEST_P(GpuBatchPasses, AFlushRunsFusedAndPerColourSheetsTogether) {
  // Sheet 5 has hash cells of 5 spacings: a CPU device's fused tick does not take it, so alone
  // and in the fleet it runs the per-colour passes, while the others run the fused tick.
  const std::vector<FleetSheet> sheets = mixedFleet(6);
  gpu::GpuBatch batch(ctx(), uint32_t(sheets.size()), GetParam());
  gpu::GpuSolver alone(ctx());
  expectFleetMatchesAlone(batch, alone, sheets, 12);
  const bool cpu_device = ctx().properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
  Simulation sim(sheets[5].params, alone);
  sim.setScript(sheets[5].script); // held by its grab, as in the fleet's last flush
  sim.tick();
  EXPECT_EQ(alone.usesFusedPath(sim.lastUniforms()), !cpu_device);
  if (cpu_device)
    EXPECT_GT(batch.dispatchesPerFlush(), alone.dispatchesPerTick()); // the fused sheets' dispatches as well
  else
    EXPECT_EQ(batch.dispatchesPerFlush(), 1u);
}

TEST_P(GpuBatchPasses, SheetsOnThePerColourPassesMatchTheCpuReference) {
  // The per-colour passes of every sheet (the fused tick forbidden, as for a sheet over its
  // capacity: LargeSheetsRecordTheDispatchesOfOneSheetPerPassOrPerSheet). Batched, each pass is one
  // dispatch for every sheet and a gate picks the sheets that run it (substeps, iterations, air,
  // collision, hash, tears, reset). Seven sheets: a yank (1, 5), a reset (2, 6), a ray grab (3),
  // tearing off (3), stiff against tearing (2), collision off (4), air (1, 6), 6 to 8 substeps, 3
  // or 4 iterations. 21 ticks: to the ray grab's release (tick 20), after the resets (15).
  const std::vector<FleetSheet> sheets = mixedFleet(7, 16, 24);
  gpu::GpuBatch batch(ctx(), uint32_t(sheets.size()), GetParam());
  batch.setFusedPath(false);
  EXPECT_EQ(batch.passesPerSheet(), GetParam() == gpu::BatchPasses::PerSheet);
  CpuSolver alone;
  const uint32_t tore = expectFleetMatchesAlone(batch, alone, sheets, 21);
  EXPECT_GT(batch.dispatchesPerFlush(), 50u); // the passes, not one fused dispatch a substep
  EXPECT_GT(tore, 0u);
  EXPECT_LT(tore, sheets.size());
}

TEST_P(GpuBatchPasses, ContactSheetsOnThePerColourPassesMatchTheirRunsAlone) {
  // Sheet 1 has contact on, sheet 0 not: batched, the contact passes' gates take sheet 1 alone
  const std::vector<FleetSheet> sheets = withContact(mixedFleet(2, 16, 24));
  gpu::GpuBatch batch(ctx(), uint32_t(sheets.size()), GetParam());
  batch.setFusedPath(false);
  CpuSolver alone;
  expectFleetMatchesAlone(batch, alone, sheets, 8);
}

// Without the candidate lists (the switch the solver and the fleet both honour), every substep with
// collision builds the hash, in a fleet's per-colour passes as alone.
TEST_P(GpuBatchPasses, WithoutCandidateListsSheetsMatchTheirRunsAlone) {
  const std::vector<FleetSheet> sheets = mixedFleet(3, 16, 24);
  gpu::GpuBatch batch(ctx(), uint32_t(sheets.size()), GetParam());
  batch.setCandidateLists(false);
  batch.setFusedPath(false);
  gpu::GpuSolver alone(ctx());
  alone.setCandidateLists(false);
  alone.setFusedPath(false);
  expectFleetMatchesAlone(batch, alone, sheets, 12);
}

TEST_P(GpuBatchPasses, LargeSheetsRecordTheDispatchesOfOneSheetPerPassOrPerSheet) {
  // Five sheets of one size: batched, the passes one of them records alone; sheet by sheet, five
  // times those
  const std::string rows = "rows=" + std::to_string(rowsPastTheFusedTick(48, 48));
  const SimParams p = cloth({"cols=48", rows.c_str()});
  gpu::GpuBatch batch(ctx(), 5, GetParam());
  Fleet fleet(batch, std::vector<FleetSheet>(5, FleetSheet{p, {}}));
  gpu::GpuSolver alone(ctx());
  Simulation sim(p, alone);
  for (int t = 0; t < 2; ++t) {
    fleet.tick();
    sim.tick();
  }
  EXPECT_GT(alone.dispatchesPerTick(), 50u);
  EXPECT_EQ(batch.dispatchesPerFlush(), alone.dispatchesPerTick() * (batch.passesPerSheet() ? 5u : 1u));
}

INSTANTIATE_TEST_SUITE_P(Fleet, GpuBatchPasses, testing::Values(gpu::BatchPasses::Batched, gpu::BatchPasses::PerSheet),
                         [](const testing::TestParamInfo<gpu::BatchPasses>& param) {
                           return param.param == gpu::BatchPasses::Batched ? std::string("batched")
                                                                           : std::string("per_sheet");
                         });

TEST_F(GpuBatchTest, ACpuDeviceRunsThePerColourPassesSheetBySheet) {
  gpu::GpuBatch batch(ctx(), 2);
  EXPECT_EQ(batch.passesPerSheet(), ctx().properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU);
}

TEST_F(GpuBatchTest, BatchedContactSheetsRecordTheDispatchesOfOneSheet) {
  // Four crumpled sheets with contact, each its own yank (their lists and grids are built in
  // different substeps): batched, the passes one sheet alone records, each sheet's contact
  // passes armed by its own arguments (sheet by sheet:
  // ContactSheetsOnThePerColourPassesMatchTheirRunsAlone and
  // LargeSheetsRecordTheDispatchesOfOneSheetPerPassOrPerSheet). The same bits as alone.
  const SimParams p = crumpleSheet({"cols=12", "rows=16"});
  std::vector<FleetSheet> sheets;
  for (uint32_t i = 0; i < 4; ++i)
    sheets.push_back({p, script(("0 grab particle " + std::to_string(191 - 5 * i) + "\n1 move " +
                                 std::to_string(1 + i) + " -2 3\n5 release\n")
                                    .c_str())});
  gpu::FusedShape passes; // contact in passes, not in the fleet's fused tick
  passes.contact = -1;
  gpu::GpuBatch batch(ctx(), uint32_t(sheets.size()), gpu::BatchPasses::Batched, passes);
  gpu::GpuSolver alone(ctx());
  alone.setFusedPath(false);
  {
    Fleet fleet(batch, std::vector<FleetSheet>(4, FleetSheet{p, {}}));
    Simulation sim(p, alone);
    for (int t = 0; t < 2; ++t) {
      fleet.tick();
      sim.tick();
    }
    EXPECT_GT(alone.dispatchesPerTick(), 100u);
    EXPECT_EQ(batch.dispatchesPerFlush(), alone.dispatchesPerTick());
  }
  gpu::GpuBatch again(ctx(), uint32_t(sheets.size()), gpu::BatchPasses::Batched, passes);
  CpuSolver cpu;
  expectFleetMatchesAlone(again, cpu, sheets, 6); // to the release at tick 5
}

} // namespace
} // namespace tender::test
