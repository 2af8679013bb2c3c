#pragma once
/// A batch of sheets on Vulkan: each of the sheet's storage buffers holds a slice per sheet, and
/// the shaders reach a sheet's slices by device address from a table (SIM_BATCH_* in sim_config.h).
/// Sheets that take the fused tick run it in one dispatch of tick_batch.comp, one workgroup each;
/// the others run the per-colour passes, each pass one dispatch for all of them (a sheet per
/// workgroup z, the pass's gate picking the sheets it runs for). Every sheet has its own uniforms
/// (parameters, wind, grab), and its arithmetic is that of the same sheet alone, so sheet i ends
/// bitwise where the same sheet run alone on the GPU solver ends.
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/fleet.h"
#include "gpu/context.h"
#include "gpu/gpu_solver.h"
#include "gpu/sheet_buffers.h"
#include "gpu/sim_pipeline.h"
#include "gpu/substep_passes.h"

namespace tender::gpu {

/// How a batch runs the per-colour passes of the sheets the fused tick does not take. Both give
/// every sheet the bits of its run alone.
enum class BatchPasses : uint8_t {
  Auto,    ///< Batched on a GPU, PerSheet on a CPU device
  Batched, ///< each pass one dispatch for every sheet (a sheet per workgroup z, the SIM_BATCH_PASS builds)
  /// each sheet's passes in turn, on a descriptor set over its slices (the solver's own shaders):
  /// a CPU device runs these faster, its cost being per workgroup rather than per dispatch
  PerSheet,
};

class GpuBatch final : public SheetBatch, private PassSink {
public:
  /// A batch of `sheets` sheets on an existing context (it must outlive the batch). Throws with
  /// one line when the device cannot run it (no device addresses).
  GpuBatch(VulkanContext& ctx, uint32_t sheets, BatchPasses passes = BatchPasses::Auto, FusedShape fused = {});
  /// A batch that owns its context.
  GpuBatch(std::unique_ptr<VulkanContext> ctx, uint32_t sheets, FusedShape fused = {});
  /// True when the per-colour passes run sheet by sheet (BatchPasses::PerSheet).
  bool passesPerSheet() const { return per_sheet_; }
  /// Keeps (default) or drops the collision candidate lists, as GpuSolver::setCandidateLists.
  void setCandidateLists(bool keep) { candidates_allowed_ = keep; }
  /// Allows (default) or forbids the fused tick, as GpuSolver::setFusedPath: forbidden, every sheet
  /// runs the per-colour passes, whatever its size.
  void setFusedPath(bool allowed) { fused_allowed_ = allowed; }
  ~GpuBatch() override;
  GpuBatch(const GpuBatch&) = delete;
  GpuBatch& operator=(const GpuBatch&) = delete;

  std::string name() const override { return "gpu"; }
  uint32_t size() const override { return uint32_t(queued_.size()); }
  Solver& sheet(uint32_t i) override { return *queued_[i]; }
  void flush() override;
  void finish() override;
  uint64_t memoryBytes() const override;
  uint32_t dispatchesPerFlush() const override { return last_dispatches_; }
  void readPositions(std::vector<glm::vec4>& pos, std::vector<glm::vec4>& prev) override;
  VulkanContext& context() { return ctx_; }

private:
  class Sheet;
  friend class Sheet;

  /// Slices start at this alignment (every binding's slice of every sheet).
  static constexpr VkDeviceSize kSliceAlign = 256;
  /// The batch's indirect arguments.
  static constexpr VkDeviceSize kArgsBytes = 16ull * SIM_BATCH_ARGS_COUNT;

  void create(uint32_t sheets, BatchPasses passes, FusedShape fused);
  /// The sheets a flush ticks, by the path each takes alone, and where the inputs buffer holds
  /// their uniforms and the batch's indirect arguments (takeQueued).
  struct FlushQueue {
    std::vector<uint32_t> fused, fused_contact, passes; ///< sheets of the fused tick, with contact, of the passes
    std::vector<shaderio::SimUniforms> pass_uniforms;   /// the uniforms of the passes' sheets, in their order
    uint32_t fused_substeps = 0, pass_substeps = 0;     ///< the most substeps of each path
    SubstepPlan plan;                                   ///< the union of the passes' sheets' plans
    bool resets = false;                                ///< one of the passes' sheets resets
    VkDeviceSize uniforms_at = 0, args_at = 0;
    /// The queue the shaders read: the fused sheets without contact, those with, then the others.
    std::vector<uint32_t> queue() const;
  };
  /// Takes the queued sheets' uniforms into the inputs buffer and sorts the sheets by path.
  FlushQueue takeQueued();
  /// Records the copies of the inputs (uniforms, queue, indirect arguments) to the device.
  void recordInputs(const FlushQueue& f);
  /// Records the fused tick of `count` sheets from queue[queue_first] with `pipe`, `substeps` each.
  void recordFusedTicks(const ComputePipeline& pipe, uint32_t queue_first, uint32_t count, uint32_t substeps);
  /// Records each passes' sheet's per-colour passes on its own descriptor set (PerSheet).
  void recordSheetPasses(const FlushQueue& f);
  /// Records the per-colour passes once for all the passes' sheets (Batched), and their arguments.
  void recordBatchedPasses(const FlushQueue& f);
  // PassSink: a pass of the per-colour path for the sheets at queue[pass_first_, + pass_sheets_)
  void pass(const ComputePipeline& p, Grid grid, uint32_t count, const void* push, uint32_t push_size, uint32_t substep,
            const PassGate& gate) override;
  /// PerSheet: a pass of sheet i on its descriptor set (bound), as the solver dispatches it.
  void passOfSheet(uint32_t i, const ComputePipeline& p, Grid grid, uint32_t count, const void* push,
                   uint32_t push_size, uint32_t arg);
  void barrier() override;
  void mark(PassCategory) override {}
  /// Allocates every buffer for the batch from the first sheet's topology.
  void allocate(const SheetTopology& topo);
  void uploadSheet(uint32_t i, const SheetTopology& topo);
  void resetSheet(uint32_t i);
  void readSheet(uint32_t i, SimState& out);
  glm::vec4 readParticle(uint32_t i, uint32_t particle);
  std::vector<glm::vec4> readSheetPositions(uint32_t i);
  /// Sheet i's particles in contact in its last tick (Solver::contacts; -1: contact was off).
  int64_t sheetContacts(uint32_t i);
  void readSheetDeltas(uint32_t i, std::vector<glm::vec4>& out);
  /// Where sheet i's bindings live: its slices.
  SheetPlace place(uint32_t i) const;
  VkDeviceSize sliceOffset(uint32_t binding, uint32_t sheet) const { return stride_[binding] * sheet; }

  std::unique_ptr<VulkanContext> owned_ctx_;
  VulkanContext& ctx_;
  std::vector<std::unique_ptr<Sheet>> sheets_;
  std::vector<std::unique_ptr<QueuedSolver>> queued_;

  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  ComputePipeline tick_batch_;         ///< the fused tick of a batch (null until a flush first runs it)
  ComputePipeline tick_batch_contact_; ///< ... with contact's bodies (made when a sheet first takes it)
  uint32_t fused_workgroup_ = 0;       ///< the fused tick's workgroup (FusedShape)
  bool fused_contact_ = false;         ///< sheets with contact take the fused tick (FusedShape::contact)
  SimPipelines passes_;                ///< the per-colour passes of a batch (SIM_BATCH_PASS)
  bool per_sheet_ = false;             ///< BatchPasses::PerSheet
  bool candidates_allowed_ = true;     ///< setCandidateLists
  bool fused_allowed_ = true;          ///< setFusedPath
  VkDescriptorSetLayout sheet_set_layout_ = VK_NULL_HANDLE; ///< PerSheet: a sheet's set, as the solver's
  VkPipelineLayout sheet_layout_ = VK_NULL_HANDLE;
  VkDescriptorPool sheet_pool_ = VK_NULL_HANDLE;
  std::vector<VkDescriptorSet> sheet_sets_;   ///< PerSheet: each sheet's set over its slices
  SimPipelines sheet_passes_;                 ///< PerSheet: the solver's passes
  int64_t pass_sheet_ = -1;                   ///< PerSheet: the sheet whose passes are being recorded
  float fused_max_cell_spacings_ = -1.0f;     ///< largest hash cell the fused tick takes (< 0: any; FusedShape)
  float spacing_ = 0.0f;                      ///< the sheets' grid spacing
  uint32_t pass_first_ = 0, pass_sheets_ = 0; ///< the sheets in the queue the passes being recorded run for
  HashGrids hash_grids_;                      ///< full grids of the hash passes, in recording order
  VkPipeline bound_ = VK_NULL_HANDLE;         ///< pipeline bound while recording
  FloatRules float_rules_;
  MathSwitches math_;
  uint32_t substeps_per_dispatch_ = 1;
  uint32_t sheets_per_group_ = 1; ///< sheets a dispatch of a CPU device takes (a substep each)

  SheetTopology topo_; ///< the topology every sheet shares
  SheetLayout sizes_;
  bool allocated_ = false;
  bool ticked_ = false;          ///< a sheet has ticked
  std::vector<bool> uploaded_;   ///< the sheets uploaded
  std::vector<bool> contact_on_; ///< the sheets whose last tick had contact on
  /// Frees every slice (allocate makes them again).
  void releaseSlices();
  std::array<Buffer, SIM_BATCH_ENTRIES> buf_{};          ///< per binding: a slice per sheet; the queue
  std::array<VkDeviceSize, SIM_BATCH_ENTRIES> stride_{}; ///< bytes from one sheet's slice to the next
  Buffer table_;                                         ///< SIM_BATCH_ENTRIES uvec4 (device)
  VkDeviceAddress table_address_ = 0;                    ///< its device address (the shaders' push constants)
  Buffer inputs_; ///< host: the queue, the uniforms of each sheet, then the batch's indirect arguments

  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  bool pending_ = false;
  uint32_t last_dispatches_ = 0;
};

} // namespace tender::gpu
