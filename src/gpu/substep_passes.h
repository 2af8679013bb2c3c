#pragma once
/// The passes of one substep of the per-colour path, as the pass table says (SIM_STAGES and
/// SIM_DISPATCHES, shaders/shared/sim_passes.h), recorded into a PassSink: the GPU solver dispatches them for its
/// sheet; a fleet dispatches each for every sheet of a batch, and its gate (PassGate) picks the sheets that run it,
/// those that would run it alone.
#include <cstdint>
#include <vector>

#include "core/sheet.h"
#include "gpu/sheet_buffers.h"
#include "gpu/sim_pipeline.h"

namespace tender::gpu {

/// How a dispatch gets its grid: from the element count, one workgroup, the tear compaction's
/// arguments (zero workgroups unless something tore), the next live hash-pass argument (zero
/// workgroups when the candidate lists stand in for the hash), the next live argument of
/// contact's grid passes (zero workgroups in a substep that does not build the grid),
/// contact_walk's (the queries with pairs in their lists; none in a substep that builds them),
/// contact_cross's, the queries with pairs in their lists (Named: contact_emit's, for the passes
/// that weigh them again after the floor), or the settle stage's: its half-spaces' passes (Settle) and each sweep's
/// (Sweep), zero workgroups until an edge over the limit (or the sweep before) arms them.
enum class Grid : uint8_t { Threads, Workgroup, Compaction, Hash, Contact, Walk, Cross, Named, Settle, Sweep };

/// Timestamp categories of a tick, in Solver::passTimes() order (SIM_DISPATCHES' category column
/// names the first six). kFused: the fused small-sheet tick, every pass in one dispatch.
enum PassCategory : uint8_t {
  kContact,
  kIntegrate,
  kProject,
  kHash,
  kCollide,
  kFloor,
  kTear,
  kNormals,
  kFused,
  kCategoryCount
};

/// The full grid of `count` elements of `p`, with `sheets` workgroups in z: wider than
/// SIM_MAX_GROUPS_X spills into y (the shaders linearise the group index).
glm::uvec4 fullGrid(const ComputePipeline& p, uint32_t count, uint32_t sheets = 1);

/// The full grids of the indirect passes, in recording order: every substep records the same hash
/// passes as the same hash dispatches (at most SIM_HASH_DISPATCHES), and the same grid passes of
/// contact (at most SIM_CONTACT_GRID_DISPATCHES), whose live arguments the passes dispatch from.
class HashGrids {
public:
  /// A pass of grid `grid` is recorded. A hash (or contact grid) pass of full grid `full` is the
  /// next dispatch of its kind and returns the slot of its live argument in SIM_BIND_HASH_ARGS
  /// (its grid checked against earlier substeps'); a settle pass returns its slot there (for
  /// Grid::Sweep the sweep `arg` names, as for a fleet's gate); any other pass makes the next
  /// of each kind the first.
  uint32_t record(Grid grid, glm::uvec4 full, uint32_t arg = 0);
  /// The hash passes' full grids (from slot SIM_HASH_DISPATCHES)
  const std::vector<glm::uvec4>& grids() const { return grids_; }
  /// Contact's grid passes' full grids (from slot SIM_CONTACT_GRID_ARGS + SIM_CONTACT_GRID_DISPATCHES)
  const std::vector<glm::uvec4>& contactGrids() const { return contact_grids_; }
  /// A settle sweep's full grid (at SIM_CONTACT_SETTLE_FULL; the half-spaces' passes take the
  /// named queries' grid)
  glm::uvec4 sweepGrid() const { return sweep_grid_; }
  void clear() {
    grids_.clear();
    contact_grids_.clear();
    sweep_grid_ = glm::uvec4(0u);
    next_ = next_contact_ = 0;
  }

private:
  std::vector<glm::uvec4> grids_, contact_grids_;
  glm::uvec4 sweep_grid_{0u};
  uint32_t next_ = 0, next_contact_ = 0;
};

/// Where one sheet's arrays and indirect arguments are bound for its passes.
struct SheetPassTarget {
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE; ///< the sheet's descriptor set is bound on it
  VkBuffer hash_args = VK_NULL_HANDLE;      ///< its SIM_BIND_HASH_ARGS (live arguments from hash_offset)
  VkDeviceSize hash_offset = 0;
  VkBuffer counters = VK_NULL_HANDLE; ///< its SIM_BIND_COUNTERS (the Counters from counters_offset)
  VkDeviceSize counters_offset = 0;
};

/// Records a pass of one sheet on its descriptor set, as the solver dispatches it: `count`
/// elements (Grid::Threads; none: nothing recorded), one workgroup, the compaction's indirect
/// arguments, or the next hash dispatch's live arguments (Grid::Sweep: those of the settle sweep
/// `arg` names). `bound` is the pipeline bound on `t.cmd`. Returns false when nothing was
/// recorded.
bool recordSheetPass(const SheetPassTarget& t, VkPipeline& bound, HashGrids& hash_grids, const ComputePipeline& p,
                     Grid grid, uint32_t count, const void* push, uint32_t push_size, uint32_t arg = 0);

/// Which sheets of a batch run a pass (BatchArgs): those that meet its conditions, of those the ones
/// its run-time gate takes.
struct PassGate {
  uint32_t when = SIM_WHEN_ALWAYS; ///< SIM_WHEN_* bits, its stage's and its own (stageConditions)
  uint32_t live = SIM_LIVE_NONE;   ///< SIM_LIVE_*
  uint32_t arg = 0;                ///< SIM_LIVE_ITERATION: the iteration; SIM_LIVE_SWEEP: the sweep
};

/// Where the passes of a substep go.
class PassSink {
public:
  /// A pass of substep `substep`: `count` elements of `p` (Grid::Threads) or the grid `grid` names,
  /// with `push_size` bytes of push constants; `gate` says which sheets of a batch run it.
  virtual void pass(const ComputePipeline& p, Grid grid, uint32_t count, const void* push, uint32_t push_size,
                    uint32_t substep, const PassGate& gate) = 0;
  /// What the passes recorded so far wrote is seen by the next.
  virtual void barrier() = 0;
  /// The passes recorded since the last mark belong to category `c` (timestamps).
  virtual void mark(PassCategory c) = 0;

protected:
  ~PassSink() = default;
};

/// What the passes of a substep cover: a sheet's from its uniforms (substepPlan); for a fleet, the
/// union of its sheets' (add): the most iterations and sweeps, and each pass any sheet runs.
struct SubstepPlan {
  uint32_t iterations = 0;
  uint32_t when = SIM_WHEN_ALWAYS; ///< the conditions met (SIM_WHEN_* bits, stageConditions)
  uint32_t stop = SIM_NONE;        ///< last pass to record (SIM_STAGES numbering; Solver::stopNextTickAfter)
  uint32_t sweeps = 0;             ///< the settle stage's sweeps (SimUniforms::contact_check.sweeps)

  /// Widens this plan to cover `other`'s passes as well (its stop is kept).
  void add(const SubstepPlan& other);
  bool operator==(const SubstepPlan&) const = default;
};

/// The plan of a sheet's substeps from its uniforms, recording up to pass `stop`.
SubstepPlan substepPlan(const shaderio::SimUniforms& u, uint32_t stop = SIM_NONE);

/// Timestamps a substep of the per-colour path records (one where each category ends).
uint32_t marksPerSubstep();

/// Records the passes of substep `s` of a sheet of this topology and layout; `pass` counts them.
/// Returns true when the tick stops within it (SubstepPlan::stop).
bool recordSubstep(PassSink& sink, const SimPipelines& pipes, const SheetTopology& topo, const SheetLayout& sizes,
                   const SubstepPlan& plan, uint32_t s, uint32_t& pass);

} // namespace tender::gpu
