// GpuBatch's flush: the ticks queued since the last one, recorded into one command buffer (the
// fused tick's sheets in one dispatch, the rest through the per-colour passes, batched) and
// submitted; gpu_batch.cpp creates the batch and records its passes.
#include <algorithm>
#include <cstring>
#include <stdexcept>

#include "core/host_queries.h"
#include "gpu/barriers.h"
#include "gpu/gpu_solver.h"
#include "gpu_batch.h"

namespace tender::gpu {

using namespace shaderio;

std::vector<uint32_t> GpuBatch::FlushQueue::queue() const {
  std::vector<uint32_t> q = fused;
  q.insert(q.end(), fused_contact.begin(), fused_contact.end());
  q.insert(q.end(), passes.begin(), passes.end());
  return q;
}

GpuBatch::FlushQueue GpuBatch::takeQueued() {
  // Each sheet takes the path it takes alone: the fused tick or the per-colour passes
  FlushQueue f;
  const bool fits_fused = fused_allowed_ && fusedTickFits(topo_, fusedCapacity(ctx_));
  f.uniforms_at = alignUp(4ull * size(), kSliceAlign);
  f.args_at = f.uniforms_at + stride_[SIM_BIND_UNIFORMS] * size();
  char* inputs = static_cast<char*>(inputs_.mapped);
  for (uint32_t i = 0; i < size(); ++i) {
    auto& q = queued_[i]->queued();
    if (!q) continue;
    SimUniforms u = *q;
    q.reset();
    if (u.contact.radius > 0.0f) {
      // The fleet sized its contact buffers when a sheet was made with contact on
      if (!sizes_.contact)
        throw std::runtime_error("contact_factor was turned on in a fleet made without it: a fleet on the GPU "
                                 "needs it set when its sheets are made");
      u.contact_grid = {sizes_.contact_buckets / 2 - 1, sizes_.contact_counts, sizes_.contact_fill,
                        sizes_.contact_edges};
      u.contact_check.half_offset = sizes_.contact_half;
      u.contact_check.list_capacity = SIM_CONTACT_LIST_CAPACITY;
    }
    ticked_ = true;
    contact_on_[i] = u.contact.radius > 0.0f;
    if (keepsCandidateLists(sizes_, candidates_allowed_)) u.flags |= SIM_FLAG_CANDIDATES; // as the solver does
    std::memcpy(inputs + f.uniforms_at + stride_[SIM_BIND_UNIFORMS] * i, &u, sizeof(u));
    const uint32_t substeps = u.reset_active ? 0u : substepCount(u.substeps);
    // A sheet with contact takes the fused tick with contact's bodies where the device's shape runs
    // them in the workgroup (FusedShape::contact), the per-colour passes elsewhere
    const bool contact = u.contact.radius > 0.0f;
    if (fits_fused && fusedTickTakes(u, spacing_, fused_max_cell_spacings_, fused_contact_)) {
      f.fused_substeps = std::max(f.fused_substeps, std::max(substeps, 1u));
      (contact ? f.fused_contact : f.fused).push_back(i);
      continue;
    }
    f.passes.push_back(i);
    f.pass_uniforms.push_back(u);
    f.resets = f.resets || u.reset_active;
    if (u.reset_active) continue;
    f.pass_substeps = std::max(f.pass_substeps, substeps);
    f.plan.add(substepPlan(u));
  }
  return f;
}

void GpuBatch::recordInputs(const FlushQueue& f) {
  const std::vector<uint32_t> queue = f.queue();
  std::memcpy(inputs_.mapped, queue.data(), 4 * queue.size());
  // Work submitted before (uploads, resets, the last flush) is done before the copies.
  allToAll(cmd_);
  std::vector<VkBufferCopy> regions;
  for (uint32_t i : queue)
    regions.push_back(
        {f.uniforms_at + stride_[SIM_BIND_UNIFORMS] * i, sliceOffset(SIM_BIND_UNIFORMS, i), sizeof(SimUniforms)});
  vkCmdCopyBuffer(cmd_, inputs_.buffer, buf_[SIM_BIND_UNIFORMS].buffer, uint32_t(regions.size()), regions.data());
  VkBufferCopy queue_region{0, 0, 4ull * queue.size()};
  vkCmdCopyBuffer(cmd_, inputs_.buffer, buf_[SIM_BATCH_QUEUE].buffer, 1, &queue_region);
  if (!f.passes.empty() && per_sheet_) {
    // Each sheet's full grids of the hash passes, of contact's grid passes and of the settle's,
    // which its candidates_decide, contact_arm and settle passes copy to the live ones
    std::vector<VkBufferCopy> grid_regions;
    for (uint32_t i : f.passes) {
      grid_regions.push_back(
          {f.args_at, sliceOffset(SIM_BIND_HASH_ARGS, i) + 16ull * SIM_HASH_DISPATCHES, 16ull * SIM_HASH_DISPATCHES});
      grid_regions.push_back(
          {f.args_at + 16ull * SIM_HASH_DISPATCHES,
           sliceOffset(SIM_BIND_HASH_ARGS, i) + 16ull * (SIM_CONTACT_GRID_ARGS + SIM_CONTACT_GRID_DISPATCHES),
           16ull * SIM_CONTACT_GRID_DISPATCHES});
      grid_regions.push_back({f.args_at + 16ull * (SIM_HASH_DISPATCHES + SIM_CONTACT_GRID_DISPATCHES),
                              sliceOffset(SIM_BIND_HASH_ARGS, i) + 16ull * SIM_CONTACT_SETTLE_FULL, 16ull});
    }
    vkCmdCopyBuffer(cmd_, inputs_.buffer, buf_[SIM_BIND_HASH_ARGS].buffer, uint32_t(grid_regions.size()),
                    grid_regions.data());
  } else if (!f.passes.empty()) {
    VkBufferCopy args_region{f.args_at, 0, kArgsBytes};
    vkCmdCopyBuffer(cmd_, inputs_.buffer, buf_[SIM_BATCH_ARGS].buffer, 1, &args_region);
  }
  // ... seen by the passes and by their indirect dispatches
  memoryBarrier(cmd_, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT,
                VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT |
                    VK_ACCESS_2_UNIFORM_READ_BIT | VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT);
}

// On a GPU one dispatch runs every fused sheet's whole tick (one more for the sheets with contact).
// A CPU device runs a substep per dispatch (SIM_FUSED_SUBSTEPS_CPU): it takes the sheets a few at a
// time, each few through every substep, so that their arrays stay in the cache from one substep to
// the next.
void GpuBatch::recordFusedTicks(const ComputePipeline& pipe, uint32_t queue_first, uint32_t count, uint32_t substeps) {
  if (count == 0) return;
  const VkDeviceAddress table = table_address_;
  vkCmdBindPipeline(cmd_, VK_PIPELINE_BIND_POINT_COMPUTE, pipe.pipeline);
  bound_ = pipe.pipeline;
  const uint32_t per_group = substeps_per_dispatch_ >= substeps ? count : sheets_per_group_;
  for (uint32_t first_sheet = 0; first_sheet < count; first_sheet += per_group)
    for (uint32_t first = 0; first < substeps; first += substeps_per_dispatch_) {
      if (first > 0) computeToCompute(cmd_);
      BatchPush push{};
      push.fused = {topo_.particleCount(), first, substeps_per_dispatch_, SIM_NONE};
      push.batch.table = glm::uvec2(uint32_t(table), uint32_t(table >> 32));
      push.batch.first = queue_first + first_sheet;
      vkCmdPushConstants(cmd_, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push), &push);
      vkCmdDispatch(cmd_, std::min(per_group, count - first_sheet), 1, 1);
      ++last_dispatches_;
    }
}

void GpuBatch::recordSheetPasses(const FlushQueue& f) {
  // Each sheet's per-colour passes, on its own descriptor set, as it records them alone
  const uint32_t n = topo_.particleCount();
  hash_grids_.clear();
  for (size_t k = 0; k < f.passes.size(); ++k) {
    const SimUniforms& u = f.pass_uniforms[k];
    pass_sheet_ = f.passes[k];
    const uint32_t zero = 0;
    vkCmdBindDescriptorSets(cmd_, VK_PIPELINE_BIND_POINT_COMPUTE, sheet_layout_, 0, 1, &sheet_sets_[f.passes[k]], 1,
                            &zero);
    uint32_t count = 0;
    if (u.reset_active) {
      const SimPush all{0, n, 0, 0};
      pass(sheet_passes_.reset, Grid::Threads, n, &all, sizeof(all), 0, PassGate{SIM_WHEN_ALWAYS, SIM_LIVE_RESET, 0});
      continue;
    }
    const SubstepPlan sheet_plan = substepPlan(u);
    for (uint32_t s = 0; s < substepCount(u.substeps); ++s)
      recordSubstep(*this, sheet_passes_, topo_, sizes_, sheet_plan, s, count);
  }
  pass_sheet_ = -1;
  glm::uvec4 grids[SIM_HASH_DISPATCHES + SIM_CONTACT_GRID_DISPATCHES + 1] = {};
  std::copy(hash_grids_.grids().begin(), hash_grids_.grids().end(), grids);
  std::copy(hash_grids_.contactGrids().begin(), hash_grids_.contactGrids().end(), grids + SIM_HASH_DISPATCHES);
  grids[SIM_HASH_DISPATCHES + SIM_CONTACT_GRID_DISPATCHES] = hash_grids_.sweepGrid();
  std::memcpy(static_cast<char*>(inputs_.mapped) + f.args_at, grids, sizeof(grids));
}

void GpuBatch::recordBatchedPasses(const FlushQueue& f) {
  // The per-colour passes of the most substeps and iterations, each for every sheet; a sheet runs
  // those it runs alone (the gates). They touch other sheets' slices than the fused tick.
  pass_first_ = uint32_t(f.fused.size() + f.fused_contact.size());
  pass_sheets_ = uint32_t(f.passes.size());
  const uint32_t n = topo_.particleCount();
  if (f.resets) {
    const SimPush all{0, n, 0, 0};
    pass(passes_.reset, Grid::Threads, n, &all, sizeof(all), 0, PassGate{SIM_WHEN_ALWAYS, SIM_LIVE_RESET, 0});
    barrier();
  }
  uint32_t count = 0;
  hash_grids_.clear();
  for (uint32_t s = 0; s < f.pass_substeps; ++s) recordSubstep(*this, passes_, topo_, sizes_, f.plan, s, count);
  // The batch's indirect arguments (recordInputs's copy takes them at submission): the full grids,
  // and the live ones of every substep with no workgroups until a sheet needs them
  std::vector<glm::uvec4> args(SIM_BATCH_ARGS_COUNT, glm::uvec4(0u));
  const uint32_t compact_groups = (sizes_.tear_slots + SIM_WG_TEAR - 1) / SIM_WG_TEAR;
  args[SIM_BATCH_ARGS_FULL_COMPACT] = glm::uvec4(groupGrid(compact_groups), pass_sheets_, 0);
  for (uint32_t k = 0; k < hash_grids_.grids().size(); ++k) args[k] = hash_grids_.grids()[k];
  for (uint32_t k = 0; k < hash_grids_.contactGrids().size(); ++k)
    args[SIM_BATCH_ARGS_FULL_CONTACT + k] = hash_grids_.contactGrids()[k];
  args[SIM_BATCH_ARGS_FULL_SETTLE] = hash_grids_.sweepGrid();
  for (uint32_t s = 0; s < SIM_MAX_SUBSTEPS; ++s) {
    for (uint32_t k = 0; k < SIM_HASH_DISPATCHES; ++k)
      args[SIM_BATCH_ARGS_LIVE_HASH + s * SIM_HASH_DISPATCHES + k] = glm::uvec4(0, args[k].y, pass_sheets_, 0);
    args[SIM_BATCH_ARGS_LIVE_COMPACT + s] = glm::uvec4(0, args[SIM_BATCH_ARGS_FULL_COMPACT].y, pass_sheets_, 0);
    // Contact's grid passes, then contact_walk's, contact_cross's and the named queries' (each sheet
    // raises x and y)
    const uint32_t live = SIM_BATCH_ARGS_LIVE_CONTACT + s * SIM_BATCH_CONTACT_SLOTS;
    for (uint32_t k = 0; k < SIM_CONTACT_GRID_DISPATCHES; ++k)
      args[live + k] = glm::uvec4(0, args[SIM_BATCH_ARGS_FULL_CONTACT + k].y, pass_sheets_, 0);
    for (uint32_t k = 0; k < 3; ++k) args[live + SIM_CONTACT_GRID_DISPATCHES + k] = glm::uvec4(0, 0, pass_sheets_, 0);
    // The settle's half-spaces' passes (a sheet raises x and y to its named queries' grid), then its
    // sweeps (x to the full grid's)
    for (uint32_t k = 0; k < SIM_CONTACT_SETTLE_SLOTS; ++k)
      args[SIM_BATCH_ARGS_LIVE_SETTLE + s * SIM_CONTACT_SETTLE_SLOTS + k] =
          glm::uvec4(0, k > 0 ? args[SIM_BATCH_ARGS_FULL_SETTLE].y : 0u, pass_sheets_, 0);
  }
  std::memcpy(static_cast<char*>(inputs_.mapped) + f.args_at, args.data(), 16ull * args.size());
}

void GpuBatch::flush() {
  // The queued sheets, their uniforms into the host buffer (the last flush has finished reading it)
  finish();
  const FlushQueue f = takeQueued();
  if (f.fused.empty() && f.fused_contact.empty() && f.passes.empty()) return;
  last_dispatches_ = 0;
  // The fused ticks when a flush first runs a sheet in them (lavapipe translates a shader at every
  // pipeline it makes; a fleet on one path never runs the other's)
  if (!f.fused.empty() && !tick_batch_.pipeline)
    tick_batch_ = makeComputePipeline(ctx_, "tick_batch.comp", {layout_, "batch"}, float_rules_, math_,
                                      sizeof(BatchPush), 1, fused_workgroup_, true);
  if (!f.fused_contact.empty() && !tick_batch_contact_.pipeline)
    tick_batch_contact_ = makeComputePipeline(ctx_, "tick_batch_contact.comp", {layout_, "batch"}, float_rules_, math_,
                                              sizeof(BatchPush), 1, fused_workgroup_, true);
  if (runsWhen(SIM_WHEN_CONTACT, f.plan.when) && per_sheet_)
    addContactPipelines(ctx_, {sheet_layout_, "sheet"}, float_rules_, math_, sheet_passes_);
  else if (runsWhen(SIM_WHEN_CONTACT, f.plan.when))
    addContactPipelines(ctx_, {layout_, "batch"}, float_rules_, math_, passes_, true);

  VkCommandBufferBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(cmd_, &bi));
  recordInputs(f);
  bound_ = VK_NULL_HANDLE;
  recordFusedTicks(tick_batch_, 0, uint32_t(f.fused.size()), f.fused_substeps);
  recordFusedTicks(tick_batch_contact_, uint32_t(f.fused.size()), uint32_t(f.fused_contact.size()), f.fused_substeps);
  if (!f.passes.empty() && per_sheet_)
    recordSheetPasses(f);
  else if (!f.passes.empty())
    recordBatchedPasses(f);
  allToAllAndHost(cmd_);
  VK_CHECK(vkEndCommandBuffer(cmd_));
  ctx_.submit(cmd_, fence_);
  pending_ = true;
}

} // namespace tender::gpu
