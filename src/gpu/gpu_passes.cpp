// Recording of a tick: the fused tick's dispatches, or the substeps of the pass table
// (recordSubstep); the reset and normals command buffers.
#include <cassert>

#include "gpu/barriers.h"
#include "gpu/gpu_solver.h"

namespace tender::gpu {

using namespace shaderio;

void GpuSolver::bindSet(VkCommandBuffer cmd, uint32_t uniform_index) {
  uint32_t offset = uint32_t(uniform_index * uniform_stride_);
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, 1, &set_, 1, &offset);
  bound_ = VK_NULL_HANDLE;
}

void GpuSolver::dispatch(VkCommandBuffer cmd, const ComputePipeline& p, Grid grid, uint32_t count, const void* push,
                         uint32_t push_size, uint32_t arg) {
  const SheetPassTarget target{cmd, layout_, buf_[SIM_BIND_HASH_ARGS].buffer, 0, buf_[SIM_BIND_COUNTERS].buffer, 0};
  if (recordSheetPass(target, bound_, hash_grids_, p, grid, count, push, push_size, arg)) ++recorded_dispatches_;
}

void GpuSolver::timestamp(VkCommandBuffer cmd, InFlight& flight, PassCategory c) {
  if (!flight.queries) return;
  // Query k closes interval k - 1, which belongs to category c.
  const uint32_t q = uint32_t(flight.categories.size()) + 1;
  if (q >= query_capacity_) return;
  vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, flight.queries, q);
  flight.categories.push_back(uint8_t(c));
}

void GpuSolver::pass(const ComputePipeline& p, Grid grid, uint32_t count, const void* push, uint32_t push_size,
                     uint32_t, const PassGate& gate) {
  // One sheet: it runs every pass recorded for it
  dispatch(recording_->tick, p, grid, count, push, push_size, gate.arg);
  if (!time_kernels_) return;
  const uint32_t k = kernelOf(p.pipeline);
  if (k != SIM_NONE) timestamp(recording_->tick, *recording_, PassCategory(kCategoryCount + k));
}

void GpuSolver::barrier() { computeToCompute(recording_->tick); }

void GpuSolver::mark(PassCategory c) { timestamp(recording_->tick, *recording_, c); }

void GpuSolver::recordTick(InFlight& flight, uint32_t index, const RecordKey& key) {
  VkCommandBuffer cmd = flight.tick;
  VK_CHECK(vkResetCommandBuffer(cmd, 0));
  VkCommandBufferBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  VK_CHECK(vkBeginCommandBuffer(cmd, &bi));
  const uint32_t n = topo_.particleCount();
  recorded_dispatches_ = 0;
  flight.categories.clear();
  if (flight.queries) {
    vkCmdResetQueryPool(cmd, flight.queries, 0, query_capacity_);
    vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, flight.queries, 0);
  }
  anyToCompute(cmd); // earlier submissions (previous tick, copies, the renderer) are done
  bindSet(cmd, index);
  if (key.fused) {
    // Small sheet: every pass of fused_substeps_ substeps (on a GPU: all) in one workgroup
    const SubstepPlan& plan = key.plan;
    const uint32_t per = passesPerSubstep(plan.iterations, topo_.colorCount(), plan.when);
    const uint32_t step = fused_substeps_;
    for (uint32_t s = 0; s < key.substeps; s += step) {
      if (s > 0) computeToCompute(cmd);
      const uint32_t count = std::min(step, key.substeps - s);
      dispatch(cmd, runsWhen(SIM_WHEN_CONTACT, plan.when) ? pipes_.tick_fused_contact : pipes_.tick_fused,
               Grid::Workgroup, 1, FusedPush{n, s, count, plan.stop});
      timestamp(cmd, flight, kFused);
      if (plan.stop != SIM_NONE && plan.stop < (s + count) * per) break;
    }
  } else {
    uint32_t pass = 0;
    recording_ = &flight;
    for (uint32_t s = 0; s < key.substeps; ++s)
      if (recordSubstep(*this, pipes_, topo_, layout_sizes_, key.plan, s, pass)) break;
    recording_ = nullptr;
  }
  computeToAll(cmd); // the renderer and copies see this tick
  VK_CHECK(vkEndCommandBuffer(cmd));
  flight.recorded = key;
  // The full grids of the hash passes, of contact's grid passes and of the settle's, which
  // candidates_decide, contact_arm and the settle's passes copy to the live arguments
  if (hash_grids_.grids() != hash_grids_uploaded_ || hash_grids_.contactGrids() != contact_grids_uploaded_ ||
      hash_grids_.sweepGrid() != sweep_grid_uploaded_) {
    ctx_.submitOnce([&](VkCommandBuffer up) {
      const glm::uvec4 sweep = hash_grids_.sweepGrid();
      vkCmdUpdateBuffer(up, buf_[SIM_BIND_HASH_ARGS].buffer, VkDeviceSize(16) * SIM_CONTACT_SETTLE_FULL, 16, &sweep);
      const std::vector<glm::uvec4>&hash = hash_grids_.grids(), &contact = hash_grids_.contactGrids();
      if (!hash.empty())
        vkCmdUpdateBuffer(up, buf_[SIM_BIND_HASH_ARGS].buffer, VkDeviceSize(16) * SIM_HASH_DISPATCHES, 16 * hash.size(),
                          hash.data());
      if (!contact.empty())
        vkCmdUpdateBuffer(up, buf_[SIM_BIND_HASH_ARGS].buffer,
                          VkDeviceSize(16) * (SIM_CONTACT_GRID_ARGS + SIM_CONTACT_GRID_DISPATCHES), 16 * contact.size(),
                          contact.data());
    });
    hash_grids_uploaded_ = hash_grids_.grids();
    contact_grids_uploaded_ = hash_grids_.contactGrids();
    sweep_grid_uploaded_ = hash_grids_.sweepGrid();
  }
  flight.dispatches = recorded_dispatches_;
}

void GpuSolver::recordReset(InFlight& flight, uint32_t index) {
  VkCommandBuffer cmd = flight.reset;
  VkCommandBufferBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  VK_CHECK(vkBeginCommandBuffer(cmd, &bi));
  anyToCompute(cmd);
  bindSet(cmd, index);
  const uint32_t n = topo_.particleCount();
  dispatch(cmd, pipes_.reset, Grid::Threads, n, SimPush{0, n, 0, 0});
  computeToAll(cmd);
  VK_CHECK(vkEndCommandBuffer(cmd));
}

void GpuSolver::recordNormals() {
  VkCommandBuffer cmd = normals_cmd_;
  VkCommandBufferBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  VK_CHECK(vkBeginCommandBuffer(cmd, &bi));
  if (normals_queries_) vkCmdResetQueryPool(cmd, normals_queries_, 0, 2);
  anyToCompute(cmd);
  bindSet(cmd, kStaticUniforms);
  if (normals_queries_) vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, normals_queries_, 0);
  const uint32_t n = topo_.particleCount();
  dispatch(cmd, pipes_.normals, Grid::Threads, n, SimPush{0, n, 0, 0});
  computeToAll(cmd);
  if (normals_queries_) vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, normals_queries_, 1);
  VK_CHECK(vkEndCommandBuffer(cmd));
}

} // namespace tender::gpu
