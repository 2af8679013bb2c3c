#include "gpu/substep_passes.h"

#include <algorithm>

namespace tender::gpu {

using namespace shaderio;

glm::uvec4 fullGrid(const ComputePipeline& p, uint32_t count, uint32_t sheets) {
  const uint32_t groups = (count + p.workgroup - 1) / p.workgroup;
  const uint32_t gx = std::min<uint32_t>(groups, SIM_MAX_GROUPS_X);
  return glm::uvec4(gx, gx ? (groups + gx - 1) / gx : 0u, sheets, 0u);
}

uint32_t HashSlots::record(Grid grid, glm::uvec4 full) {
  if (grid != Grid::Hash) {
    next_ = 0;
    return 0;
  }
  const uint32_t slot = next_++;
  if (slot >= SIM_HASH_DISPATCHES) vkCheckFailed(VK_ERROR_UNKNOWN, "hash dispatches", __FILE__, __LINE__);
  if (slot == grids_.size()) grids_.push_back(full);
  if (grids_[slot] != full) vkCheckFailed(VK_ERROR_UNKNOWN, "hash grid", __FILE__, __LINE__);
  return slot;
}

bool recordSheetPass(const SheetPassTarget& t, VkPipeline& bound, HashSlots& slots, const ComputePipeline& p, Grid grid,
                     uint32_t count, const void* push, uint32_t push_size) {
  if (push_size != p.push_size) vkCheckFailed(VK_ERROR_UNKNOWN, "push constant size", __FILE__, __LINE__);
  if (grid == Grid::Threads && count == 0) return false;
  const glm::uvec4 full = fullGrid(p, count);
  const uint32_t hash_slot = slots.record(grid, full);
  if (bound != p.pipeline) {
    vkCmdBindPipeline(t.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
    bound = p.pipeline;
  }
  if (push_size) vkCmdPushConstants(t.cmd, t.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, push_size, push);
  switch (grid) {
  case Grid::Threads:
    vkCmdDispatch(t.cmd, full.x, full.y, 1);
    break;
  case Grid::Workgroup:
    vkCmdDispatch(t.cmd, 1, 1, 1);
    break;
  case Grid::Compaction:
    vkCmdDispatchIndirect(t.cmd, t.counters, t.counters_offset + offsetof(Counters, compact_dispatch));
    break;
  case Grid::Hash:
    // The live arguments candidates_decide copied from the full grids (or zero workgroups)
    vkCmdDispatchIndirect(t.cmd, t.hash_args, t.hash_offset + 16ull * hash_slot);
    break;
  }
  return true;
}

namespace {

template <class Push>
void record(PassSink& sink, const ComputePipeline& p, Grid grid, uint32_t count, const Push& push, uint32_t s,
            uint32_t gate, uint32_t gate_arg = 0) {
  sink.pass(p, grid, count, &push, uint32_t(sizeof(Push)), s, gate, gate_arg);
}

/// Exclusive scan: block scans, then (several blocks) scan the block sums and add them back.
void recordScan(PassSink& sink, const SimPipelines& pipes, uint32_t mode, uint32_t offset, uint32_t count,
                uint32_t sums, Grid grid, uint32_t s, uint32_t gate) {
  const uint32_t blocks = (count + SIM_SCAN_BLOCK - 1) / SIM_SCAN_BLOCK;
  const ScanPush push{mode, offset, count, sums};
  record(sink, pipes.scan, grid, count, push, s, gate);
  sink.barrier();
  if (blocks <= 1) return;
  recordScan(sink, pipes, SIM_SCAN_SCRATCH, sums, blocks, sums + blocks, grid, s, gate);
  record(sink, pipes.scan_add, grid, count, push, s, gate);
  sink.barrier();
}

} // namespace

bool recordSubstep(PassSink& sink, const SimPipelines& pipes, const SheetTopology& topo, const SheetLayout& sizes,
                   const SubstepPlan& plan, uint32_t s, uint32_t& pass) {
  const uint32_t n = topo.particleCount(), m = topo.constraintCount();
  const SimPush all{0, n, s, 0};
  auto stops = [&] { return pass++ == plan.stop; };
  // 1. The air on each particle (integration reads it), then Verlet integration
  if (plan.air) {
    record(sink, pipes.air, Grid::Threads, n, all, s, SIM_GATE_AIR);
    sink.barrier();
  }
  record(sink, pipes.integrate, Grid::Threads, n, all, s, SIM_GATE_TICK);
  sink.barrier();
  sink.mark(kIntegrate);
  if (stops()) return true;
  // 2. Gauss-Seidel over colours; constraints beyond a colour's live count exit
  for (uint32_t it = 0; it < plan.iterations; ++it)
    for (uint32_t c = 0; c < topo.colorCount(); ++c) {
      const ColorRange& range = topo.colors[c];
      if (range.count > 0) {
        record(sink, pipes.project, Grid::Threads, range.count, SimPush{range.first, range.count, s, c}, s,
               SIM_GATE_ITERATION, it);
        sink.barrier();
      }
      if (stops()) return true;
    }
  sink.mark(kProject);
  if (plan.collision) {
    // 3. Candidate lists still good? Spatial hash: count, scan, scatter, order within bucket
    // (each pass does nothing when the lists stand in for it); then gather repulsion and
    // update the lists' state
    record(sink, pipes.candidates_check, Grid::Threads, n, all, s, SIM_GATE_COLLISION);
    sink.barrier();
    record(sink, pipes.candidates_decide, Grid::Threads, 1, SimPush{0, SIM_HASH_DISPATCHES, s, 0}, s,
           SIM_GATE_COLLISION);
    sink.barrier();
    record(sink, pipes.hash_count, Grid::Hash, n, all, s, SIM_GATE_HASH);
    sink.barrier();
    recordScan(sink, pipes, SIM_SCAN_HASH, 0, topo.hash_size, sizes.hash_sums, Grid::Hash, s, SIM_GATE_HASH);
    record(sink, pipes.hash_scatter, Grid::Hash, n, all, s, SIM_GATE_HASH);
    sink.barrier();
    record(sink, pipes.hash_sort, Grid::Hash, n, all, s, SIM_GATE_HASH);
    sink.barrier();
    sink.mark(kHash);
    record(sink, pipes.collide, Grid::Threads, n, all, s, SIM_GATE_COLLISION);
    sink.barrier();
    record(sink, pipes.candidates_finish, Grid::Threads, 1, all, s, SIM_GATE_COLLISION);
    sink.barrier();
    sink.mark(kCollide);
    if (stops()) return true;
  }
  // 4. Collision deltas and ground contact
  record(sink, pipes.floor, Grid::Threads, n, all, s, SIM_GATE_TICK);
  sink.barrier();
  sink.mark(kFloor);
  if (stops()) return true;
  // 5. Tear marking; what stood on the triangles lost and the compaction run zero workgroups
  // unless something tore this substep
  if (m > 0) {
    record(sink, pipes.tear_mark, Grid::Threads, m, SimPush{0, m, s, 0}, s, SIM_GATE_TICK);
    sink.barrier();
    sink.pass(pipes.tear_unsupported, Grid::Compaction, 0, nullptr, 0, s, SIM_GATE_COMPACTION, 0);
    sink.barrier();
    sink.pass(pipes.tear_flags, Grid::Compaction, 0, nullptr, 0, s, SIM_GATE_COMPACTION, 0);
    sink.barrier();
    recordScan(sink, pipes, SIM_SCAN_SCRATCH, 0, sizes.tear_slots, sizes.tear_sums, Grid::Compaction, s,
               SIM_GATE_COMPACTION);
    sink.pass(pipes.tear_compact, Grid::Compaction, 0, nullptr, 0, s, SIM_GATE_COMPACTION, 0);
    sink.barrier();
  }
  sink.mark(kTear);
  return stops();
}

} // namespace tender::gpu
