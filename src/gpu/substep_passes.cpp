#include "gpu/substep_passes.h"

#include "core/passes.h"

#include <algorithm>
#include <iterator>
#include <optional>

namespace tender::gpu {

using namespace shaderio;

glm::uvec4 fullGrid(const ComputePipeline& p, uint32_t count, uint32_t sheets) {
  return glm::uvec4(groupGrid((count + p.workgroup - 1) / p.workgroup), sheets, 0u);
}

uint32_t HashGrids::record(Grid grid, glm::uvec4 full, uint32_t arg) {
  if (grid == Grid::Cross || grid == Grid::Named) return 0; // own slots, amid the contact grid's passes
  if (grid == Grid::Settle) return SIM_CONTACT_SETTLE_ARGS; // armed with the named queries' grid
  if (grid == Grid::Sweep) {                                // sweep arg's slot; every sweep has the same full grid
    if (sweep_grid_ == glm::uvec4(0u)) sweep_grid_ = full;
    if (sweep_grid_ != full || arg >= SIM_SETTLE_MAX_SWEEPS)
      vkCheckFailed(VK_ERROR_UNKNOWN, "settle grid", __FILE__, __LINE__);
    return SIM_CONTACT_SETTLE_ARGS + 1 + arg;
  }
  if (grid != Grid::Hash && grid != Grid::Contact) {
    next_ = next_contact_ = 0;
    return 0;
  }
  const bool contact = grid == Grid::Contact;
  std::vector<glm::uvec4>& grids = contact ? contact_grids_ : grids_;
  const uint32_t k = contact ? next_contact_++ : next_++;
  if (k >= (contact ? SIM_CONTACT_GRID_DISPATCHES : SIM_HASH_DISPATCHES))
    vkCheckFailed(VK_ERROR_UNKNOWN, "indirect dispatches", __FILE__, __LINE__);
  if (k == grids.size()) grids.push_back(full);
  if (grids[k] != full) vkCheckFailed(VK_ERROR_UNKNOWN, "indirect grid", __FILE__, __LINE__);
  return contact ? SIM_CONTACT_GRID_ARGS + k : k;
}

bool recordSheetPass(const SheetPassTarget& t, VkPipeline& bound, HashGrids& hash_grids, const ComputePipeline& p,
                     Grid grid, uint32_t count, const void* push, uint32_t push_size, uint32_t arg) {
  if (push_size != p.push_size) vkCheckFailed(VK_ERROR_UNKNOWN, "push constant size", __FILE__, __LINE__);
  if (grid != Grid::Workgroup && grid != Grid::Compaction && grid != Grid::Hash && count == 0) return false;
  const glm::uvec4 full = fullGrid(p, count);
  const uint32_t hash_dispatch = hash_grids.record(grid, full, arg);
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
  case Grid::Contact:
  case Grid::Settle:
  case Grid::Sweep:
    // The live arguments candidates_decide (contact_arm, the settle's passes) copied from the full
    // grids, or zero workgroups
    vkCmdDispatchIndirect(t.cmd, t.hash_args, t.hash_offset + 16ull * hash_dispatch);
    break;
  case Grid::Walk:
    // The queries with pairs in their lists at the last build, or none when they are built now
    vkCmdDispatchIndirect(t.cmd, t.hash_args, t.hash_offset + 16ull * SIM_CONTACT_WALK_ARGS);
    break;
  case Grid::Cross:
    // Every triangle when the crossing check looks at one this substep, or none
    vkCmdDispatchIndirect(t.cmd, t.hash_args, t.hash_offset + 16ull * SIM_CONTACT_CROSS_ARGS);
    break;
  case Grid::Named:
    // The queries with pairs in their lists (contact_emit)
    vkCmdDispatchIndirect(t.cmd, t.hash_args, t.hash_offset + 16ull * (SIM_CONTACT_WALK_ARGS + 1));
    break;
  }
  return true;
}

namespace {

/// What a dispatch covers (SIM_DISPATCHES' elements column).
enum class Elements : uint8_t {
  PARTICLES,
  COLOUR,
  HINGE_COLOUR,
  HINGES,
  CONSTRAINTS,
  ONE,
  RINGS,
  HASH_ARGS,
  HASH_CELLS,
  TEAR_SLOTS,
  INDIRECT,
  TRIANGLES,
  CONTACT_SLOTS,
  CONTACT_BUCKETS,
  CONTACT_BOXES,
  CONTACT_QUERIES,
  CONTACT_ACTIVE,
  CONTACT_ACTIVE_CELLS,
  CONTACT_CELLS,
  CONTACT_HALF_CELLS,
  SWEEPS
};
/// What each stage runs under (SIM_STAGES' when column).
constexpr uint32_t kStageNeeds[] = {
#define TENDER_STAGE_NEEDS(name, id, repeat, when) SIM_WHEN_##when,
    SIM_STAGES(TENDER_STAGE_NEEDS)
#undef TENDER_STAGE_NEEDS
};

/// One row of SIM_DISPATCHES.
struct Dispatch {
  uint32_t stage;
  ComputePipeline SimPipelines::*kernel;
  Elements elements;
  Grid grid;
  uint32_t when; ///< SIM_WHEN_* bits: its stage's and its own
  PassCategory category;
};

constexpr Dispatch kDispatches[] = {
#define TENDER_DISPATCH(stage, kernel, elements, grid, when, category)                                                 \
  {SIM_STAGE_##stage,                                                                                                  \
   &SimPipelines::kernel,                                                                                              \
   Elements::elements,                                                                                                 \
   Grid::grid,                                                                                                         \
   kStageNeeds[SIM_STAGE_##stage] | SIM_WHEN_##when,                                                                   \
   k##category},
    SIM_DISPATCHES(TENDER_DISPATCH)
#undef TENDER_DISPATCH
};

/// The run-time gate of a row's pass in a fleet: the grids armed at run time take a sheet whose
/// own arguments would have given it workgroups; a colour's pass, a sheet with its iteration; a
/// sweep's, a sheet with that sweep.
constexpr uint32_t liveGate(const Dispatch& d) {
  switch (d.grid) {
  case Grid::Hash:
    return SIM_LIVE_HASH;
  case Grid::Compaction:
    return SIM_LIVE_COMPACTION;
  case Grid::Contact:
    return SIM_LIVE_CONTACT_GRID;
  case Grid::Walk:
    return SIM_LIVE_CONTACT_WALK;
  case Grid::Cross:
    return SIM_LIVE_CONTACT_CROSS;
  case Grid::Sweep:
    return SIM_LIVE_SWEEP;
  default:
    return d.elements == Elements::COLOUR || d.elements == Elements::HINGE_COLOUR ? SIM_LIVE_ITERATION : SIM_LIVE_NONE;
  }
}
static_assert(std::is_sorted(std::begin(kDispatches), std::end(kDispatches),
                             [](const Dispatch& a, const Dispatch& b) { return a.stage < b.stage; }),
              "SIM_DISPATCHES lists the stages in SIM_STAGES order");

/// True when the next row (of this stage) is of another category: a timestamp closes this one.
constexpr bool closesCategory(size_t row) {
  return row + 1 == std::size(kDispatches) || kDispatches[row + 1].stage != kDispatches[row].stage ||
         kDispatches[row + 1].category != kDispatches[row].category;
}

template <class Push>
void record(PassSink& sink, const ComputePipeline& p, Grid grid, uint32_t count, const Push& push, uint32_t s,
            const PassGate& gate) {
  sink.pass(p, grid, count, &push, uint32_t(sizeof(Push)), s, gate);
}

/// Exclusive scan: block scans, then (several blocks) scan the block sums and add them back.
void recordScan(PassSink& sink, const SimPipelines& pipes, uint32_t mode, uint32_t offset, uint32_t count,
                uint32_t sums, Grid grid, uint32_t s, const PassGate& gate) {
  const uint32_t blocks = (count + SIM_SCAN_BLOCK - 1) / SIM_SCAN_BLOCK;
  const ScanPush push{mode, offset, count, sums};
  record(sink, pipes.scan, grid, count, push, s, gate);
  sink.barrier();
  if (blocks <= 1) return;
  recordScan(sink, pipes, SIM_SCAN_SCRATCH, sums, blocks, sums + blocks, grid, s, gate);
  record(sink, pipes.scan_add, grid, count, push, s, gate);
  sink.barrier();
}

/// How many elements a row's pass covers when it covers them all at once with the push
/// {0, count}; nothing for the rows recorded otherwise.
std::optional<uint32_t> wholeCount(Elements e, const SheetTopology& topo, const SheetLayout& sizes) {
  const uint32_t n = topo.particleCount();
  switch (e) {
  case Elements::PARTICLES:
    return n;
  case Elements::HINGES:
    return topo.hingeCount();
  case Elements::CONSTRAINTS:
    return topo.constraintCount();
  case Elements::TRIANGLES:
    return topo.triangleCount();
  case Elements::CONTACT_SLOTS:
    return std::max(n, sizes.contact_edges);
  case Elements::CONTACT_BUCKETS:
    return sizes.contact_buckets + 1;
  case Elements::CONTACT_BOXES:
    return topo.triangleCount() + sizes.contact_edges;
  case Elements::CONTACT_QUERIES:
    return n + sizes.contact_edges;
  default:
    return std::nullopt;
  }
}

/// The exclusive scan a row runs: its mode, where its values start, how many, where its block sums go.
struct ScanRange {
  uint32_t mode, offset, count, sums;
};

std::optional<ScanRange> scanRange(Elements e, const SheetTopology& topo, const SheetLayout& sizes) {
  const uint32_t n = topo.particleCount();
  switch (e) {
  case Elements::HASH_CELLS:
    return ScanRange{SIM_SCAN_HASH, 0, topo.hash_size, sizes.hash_sums};
  case Elements::TEAR_SLOTS:
    return ScanRange{SIM_SCAN_SCRATCH, 0, sizes.tear_slots, sizes.tear_sums};
  case Elements::CONTACT_CELLS:
    return ScanRange{SIM_SCAN_SCRATCH, sizes.contact_counts, sizes.contact_buckets + 1, sizes.contact_sums};
  case Elements::CONTACT_ACTIVE_CELLS:
    return ScanRange{SIM_SCAN_SCRATCH, sizes.contact_active, n + sizes.contact_edges + 1, sizes.contact_active_sums};
  case Elements::CONTACT_HALF_CELLS:
    return ScanRange{SIM_SCAN_SCRATCH, sizes.contact_half, n + 1, sizes.contact_half_sums};
  default:
    return std::nullopt;
  }
}

/// Pass k of a row over the colours: colour k % colours of iteration k / colours. An empty colour,
/// or one that does not project in this iteration (projectsInIteration), records nothing; nor, in
/// the shorten stage, does a colour with no edge (shortensColour). True when it recorded.
bool recordColour(PassSink& sink, const ComputePipeline& p, const SheetTopology& topo, const Dispatch& d, uint32_t s,
                  uint32_t k, PassGate gate) {
  const uint32_t c = k % topo.colorCount(), iteration = k / topo.colorCount();
  const ColorRange& range = topo.colors[c];
  if (range.count == 0) return false;
  const uint32_t kind = topo.constraints[range.first].kind_id;
  // A colour is one kind: its hinges' row or the other row records it
  if (((kind & SIM_KIND_MASK) == SIM_KIND_HINGE) != (d.elements == Elements::HINGE_COLOUR)) return false;
  if (d.stage == SIM_STAGE_shorten ? !shortensColour(kind) : !projectsInIteration(kind, iteration)) return false;
  gate.arg = iteration;
  record(sink, p, d.grid, range.count, SimPush{iteration, range.count, s, c}, s, gate);
  return true;
}

/// Records one row of SIM_DISPATCHES for pass `k` of its stage, then a barrier.
void recordDispatch(PassSink& sink, const SimPipelines& pipes, const SheetTopology& topo, const SheetLayout& sizes,
                    const Dispatch& d, uint32_t s, uint32_t k, uint32_t sweeps = 0) {
  const ComputePipeline& p = pipes.*d.kernel;
  const uint32_t n = topo.particleCount();
  PassGate gate{d.when, liveGate(d), 0};
  if (const std::optional<uint32_t> count = wholeCount(d.elements, topo, sizes)) {
    record(sink, p, d.grid, *count, SimPush{0, *count, s, 0}, s, gate);
    sink.barrier();
    return;
  }
  if (const std::optional<ScanRange> scan = scanRange(d.elements, topo, sizes)) {
    recordScan(sink, pipes, scan->mode, scan->offset, scan->count, scan->sums, d.grid, s, gate);
    return;
  }
  switch (d.elements) {
  case Elements::COLOUR:
  case Elements::HINGE_COLOUR:
    if (!recordColour(sink, p, topo, d, s, k, gate)) return;
    break;
  case Elements::ONE:
    record(sink, p, d.grid, 1, SimPush{0, n, s, 0}, s, gate);
    break;
  case Elements::RINGS: {
    // One workgroup walks each run of rings, a barrier after it
    const uint32_t per = limitRingsPerDispatch(topo.cols, topo.rows, p.workgroup),
                   most = limitMostRings(topo.cols, topo.rows);
    for (uint32_t first = 1; first <= most; first += per) {
      record(sink, p, d.grid, 1, SimPush{first, per, s, 0}, s, gate);
      if (first + per <= most) sink.barrier();
    }
    break;
  }
  case Elements::HASH_ARGS:
    record(sink, p, d.grid, 1, SimPush{0, SIM_HASH_DISPATCHES, s, 0}, s, gate);
    break;
  case Elements::INDIRECT:
    sink.pass(p, d.grid, 0, nullptr, 0, s, gate);
    break;
  case Elements::CONTACT_ACTIVE: {
    const uint32_t flags = n + sizes.contact_edges + 1;
    record(sink, p, d.grid, flags, SimPush{sizes.contact_active, flags, s, 0}, s, gate);
    break;
  }
  case Elements::SWEEPS: {
    // Each sweep, the colours with structural edges (shortensColour), a barrier after each; every
    // colour's dispatch has the largest one's grid (a sweep's indirect arguments are one slot)
    auto edges = [&](uint32_t c) {
      const ColorRange& range = topo.colors[c];
      return range.count > 0 && shortensColour(topo.constraints[range.first].kind_id) ? range.count : 0u;
    };
    uint32_t largest = 0;
    for (uint32_t c = 0; c < topo.colorCount(); ++c) largest = std::max(largest, edges(c));
    for (uint32_t sweep = 0; sweep < sweeps; ++sweep)
      for (uint32_t c = 0; c < topo.colorCount(); ++c) {
        if (edges(c) == 0) continue;
        gate.arg = sweep;
        record(sink, p, d.grid, largest, SimPush{sweep, edges(c), s, c}, s, gate);
        sink.barrier();
      }
    return;
  }
  default: // wholeCount's and scanRange's rows, recorded above
    return;
  }
  sink.barrier();
}

} // namespace

SubstepPlan substepPlan(const shaderio::SimUniforms& u, uint32_t stop) {
  SubstepPlan plan;
  plan.iterations = u.iterations;
  plan.when = conditionsOf(u);
  plan.stop = stop;
  plan.sweeps = runsWhen(SIM_WHEN_SETTLE, plan.when) ? u.contact_check.sweeps : 0u;
  return plan;
}

void SubstepPlan::add(const SubstepPlan& other) {
  iterations = std::max(iterations, other.iterations);
  when |= other.when;
  sweeps = std::max(sweeps, other.sweeps);
}

uint32_t marksPerSubstep() {
  uint32_t marks = 0;
  for (size_t row = 0; row < std::size(kDispatches); ++row) marks += closesCategory(row) ? 1u : 0u;
  return marks;
}

bool recordSubstep(PassSink& sink, const SimPipelines& pipes, const SheetTopology& topo, const SheetLayout& sizes,
                   const SubstepPlan& plan, uint32_t s, uint32_t& pass) {
  // The stages in their order, each pass of a stage its dispatches in theirs (SIM_STAGES,
  // SIM_DISPATCHES), those whose conditions the plan meets; the last pass of a stage closes its
  // timestamp categories
  for (uint32_t stage = 0; stage < SIM_STAGE_COUNT; ++stage) {
    const uint32_t passes = stagePasses(stage, plan.iterations, topo.colorCount(), plan.when);
    for (uint32_t k = 0; k < passes; ++k) {
      for (size_t row = 0; row < std::size(kDispatches); ++row) {
        const Dispatch& d = kDispatches[row];
        if (d.stage != stage) continue;
        if (runsWhen(d.when, plan.when)) recordDispatch(sink, pipes, topo, sizes, d, s, k, plan.sweeps);
        if (k + 1 == passes && closesCategory(row)) sink.mark(d.category);
      }
      if (pass++ == plan.stop) return true;
    }
  }
  return false;
}

} // namespace tender::gpu
