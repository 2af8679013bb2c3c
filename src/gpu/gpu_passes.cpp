// Recording of the simulation passes: one tick reads like the algorithm of DESIGN.md §3.
#include <cassert>

#include "gpu/barriers.h"
#include "gpu/gpu_solver.h"

namespace tender::gpu {

using namespace shaderio;

void GpuSolver::bindSet(VkCommandBuffer cmd, uint32_t uniform_slot) {
  uint32_t offset = uint32_t(uniform_slot * uniform_stride_);
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, 1, &set_, 1, &offset);
  bound_ = VK_NULL_HANDLE;
}

void GpuSolver::dispatch(VkCommandBuffer cmd, const ComputePipeline& p, Grid grid, uint32_t count, const void* push,
                         uint32_t push_size) {
  if (push_size != p.push_size) vkCheckFailed(VK_ERROR_UNKNOWN, "push constant size", __FILE__, __LINE__);
  if (grid == Grid::Threads && count == 0) return;
  // The full grid of `count` elements; wider than SIM_MAX_GROUPS_X spills into Y (the shaders
  // linearise the group index).
  const uint32_t groups = (count + p.workgroup - 1) / p.workgroup;
  const uint32_t gx = std::min<uint32_t>(groups, SIM_MAX_GROUPS_X);
  const glm::uvec4 full(gx, gx ? (groups + gx - 1) / gx : 0u, 1u, 0u);
  uint32_t hash_slot = 0;
  if (grid == Grid::Hash) {
    // Every substep records the same hash passes into the same live slots
    hash_slot = hash_slot_++;
    if (hash_slot >= SIM_HASH_DISPATCHES) vkCheckFailed(VK_ERROR_UNKNOWN, "hash dispatches", __FILE__, __LINE__);
    if (hash_slot == hash_grids_.size()) hash_grids_.push_back(full);
    if (hash_grids_[hash_slot] != full) vkCheckFailed(VK_ERROR_UNKNOWN, "hash grid", __FILE__, __LINE__);
  }
  if (bound_ != p.pipeline) {
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
    bound_ = p.pipeline;
  }
  if (push_size) vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, push_size, push);
  switch (grid) {
  case Grid::Threads:
    vkCmdDispatch(cmd, full.x, full.y, 1);
    break;
  case Grid::Workgroup:
    vkCmdDispatch(cmd, 1, 1, 1);
    break;
  case Grid::Compaction:
    vkCmdDispatchIndirect(cmd, buf_[SIM_BIND_COUNTERS].buffer, offsetof(Counters, compact_dispatch));
    break;
  case Grid::Hash:
    vkCmdDispatchIndirect(cmd, buf_[SIM_BIND_HASH_ARGS].buffer, VkDeviceSize(16) * hash_slot);
    break;
  }
  ++recorded_dispatches_;
}

void GpuSolver::timestamp(VkCommandBuffer cmd, Slot& slot, PassCategory c) {
  if (!slot.queries) return;
  // Query k closes interval k - 1, which belongs to category c.
  const uint32_t q = uint32_t(slot.categories.size()) + 1;
  if (q >= query_capacity_) return;
  vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, slot.queries, q);
  slot.categories.push_back(uint8_t(c));
}

void GpuSolver::pass(const ComputePipeline& p, Grid grid, uint32_t count, const void* push, uint32_t push_size,
                     uint32_t, uint32_t, uint32_t) {
  // One sheet: it runs every pass recorded for it. Each run of hash passes takes the live hash
  // arguments from the first.
  if (grid != Grid::Hash) hash_slot_ = 0;
  dispatch(recording_->tick, p, grid, count, push, push_size);
}

void GpuSolver::barrier() { computeToCompute(recording_->tick); }

void GpuSolver::mark(PassCategory c) { timestamp(recording_->tick, *recording_, c); }

void GpuSolver::recordTick(Slot& slot, uint32_t index, const RecordKey& key) {
  VkCommandBuffer cmd = slot.tick;
  VK_CHECK(vkResetCommandBuffer(cmd, 0));
  VkCommandBufferBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  VK_CHECK(vkBeginCommandBuffer(cmd, &bi));
  const uint32_t n = topo_.particleCount();
  recorded_dispatches_ = 0;
  slot.categories.clear();
  if (slot.queries) {
    vkCmdResetQueryPool(cmd, slot.queries, 0, query_capacity_);
    vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, slot.queries, 0);
  }
  anyToCompute(cmd); // earlier submissions (previous tick, copies, the renderer) are done
  bindSet(cmd, index);
  if (key.fused) {
    // Small sheet: every pass of fused_substeps_ substeps (on a GPU: all) in one workgroup
    const uint32_t per = passesPerSubstep(key.iterations, topo_.colorCount(), key.collision);
    for (uint32_t s = 0; s < key.substeps; s += fused_substeps_) {
      if (s > 0) computeToCompute(cmd);
      const uint32_t count = std::min(fused_substeps_, key.substeps - s);
      dispatch(cmd, pipes_.tick_fused, Grid::Workgroup, 1, FusedPush{n, s, count, key.stop});
      if (key.stop != SIM_NONE && key.stop < (s + count) * per) break;
    }
    timestamp(cmd, slot, kFused);
  } else {
    uint32_t pass = 0;
    const SubstepPlan plan{key.iterations, key.collision, key.air, key.stop};
    recording_ = &slot;
    for (uint32_t s = 0; s < key.substeps; ++s)
      if (recordSubstep(*this, pipes_, topo_, layout_sizes_, plan, s, pass)) break;
    recording_ = nullptr;
  }
  computeToAll(cmd); // the renderer and copies see this tick
  VK_CHECK(vkEndCommandBuffer(cmd));
  slot.recorded = key;
  // The full grids of the hash passes, which candidates_decide copies to the live slots
  if (hash_grids_ != hash_grids_uploaded_) {
    ctx_.submitOnce([&](VkCommandBuffer up) {
      vkCmdUpdateBuffer(up, buf_[SIM_BIND_HASH_ARGS].buffer, VkDeviceSize(16) * SIM_HASH_DISPATCHES,
                        16 * hash_grids_.size(), hash_grids_.data());
    });
    hash_grids_uploaded_ = hash_grids_;
  }
  slot.dispatches = recorded_dispatches_;
}

void GpuSolver::recordReset(Slot& slot, uint32_t index) {
  VkCommandBuffer cmd = slot.reset;
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
  bindSet(cmd, kStaticSlot);
  if (normals_queries_) vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, normals_queries_, 0);
  const uint32_t n = topo_.particleCount();
  dispatch(cmd, pipes_.normals, Grid::Threads, n, SimPush{0, n, 0, 0});
  computeToAll(cmd);
  if (normals_queries_) vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, normals_queries_, 1);
  VK_CHECK(vkEndCommandBuffer(cmd));
}

} // namespace tender::gpu
