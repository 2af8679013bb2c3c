#pragma once
/// The Vulkan compute solver: the CPU reference's passes, in the same order, over storage buffers.
/// One descriptor set holds every array (bindings in shaders/shared/sim_config.h); the tick's
/// command buffers are recorded once and re-recorded only when substeps, iterations or the
/// collision flag change; nothing is read back in the steady-state loop. Two ticks may be in
/// flight: each has its own uniforms, command buffer, fence and timestamp pool.
#include <array>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "core/solver.h"
#include "gpu/context.h"
#include "gpu/sheet_buffers.h"
#include "gpu/sim_pipeline.h"
#include "gpu/substep_passes.h"

namespace tender::gpu {

/// Shape of the fused small-sheet tick; 0 picks the device's value. On a CPU device (lavapipe):
/// SIM_WG_FUSED_CPU invocations, SIM_FUSED_SUBSTEPS_CPU substeps per dispatch, and only with hash
/// cells of at most SIM_FUSED_CPU_MAX_CELL_SPACINGS grid spacings; on a GPU: SIM_WG_FUSED
/// invocations (SIM_WG_FUSED_FLEET in a fleet), the whole tick in one dispatch, any cell.
struct FusedShape {
  uint32_t workgroup = 0;             ///< invocations of the workgroup, at most SIM_WG_FUSED_MAX
  uint32_t substeps_per_dispatch = 0; ///< substeps each dispatch runs
  float max_cell_spacings = 0.0f;     ///< largest hash cell (in grid spacings) with collision on; < 0: any
  /// With contact on: 1, the fused tick's workgroup runs contact's bodies too (a GPU's); -1, a
  /// sheet with contact takes the per-colour passes (a CPU device's, alone or in a fleet); 0: the
  /// device's kind decides. Lavapipe ends a dispatch's loops once a SIMD group has run 65535
  /// iterations (bench/README.md, "Fused small sheets"), and contact's loops in a crumpled sheet
  /// have no such bound: the hand's crumple of a 32 x 48 `crumple` sheet ran past it in the
  /// settle's sweeps and parted from the CPU's bits in tick 4.
  int contact = 0;
};

/// The fused tick's shape on this device, for a sheet alone or a `fleet`'s sheets: what `requested`
/// sets, the device's kind's values for the rest.
FusedShape resolveFusedShape(const VulkanContext& ctx, FusedShape requested = {}, bool fleet = false);

/// The grid spacing of a topology: its shortest structural rest length.
float structuralSpacing(const SheetTopology& topo);

/// True when a sheet of this topology is small enough for the fused tick of a device that holds
/// `capacity` particles (fusedCapacity): at most that many, and at most twice as many hash buckets.
bool fusedTickFits(const SheetTopology& topo, uint32_t capacity);
/// True when a tick with these uniforms, of a sheet of grid spacing `spacing` that fits the fused
/// tick, takes it on a device whose fused tick takes hash cells of at most `max_cell_spacings`
/// spacings (< 0: any) when collision is on, and with contact on only when its workgroup runs
/// contact (`contact_in_workgroup`: FusedShape::contact). The solver and a fleet both ask it.
bool fusedTickTakes(const shaderio::SimUniforms& u, float spacing, float max_cell_spacings, bool contact_in_workgroup);

/// The Solver on Vulkan compute. A substep's passes (the pass table, sim_passes.h) are recorded
/// by recordSubstep (substep_passes.h), the tear compaction and the hash passes as indirect dispatches
/// (zero workgroups when nothing tore or the candidate lists stand in). Small sheets run every pass of a substep in one
/// workgroup (tick_fused.comp): on a GPU the whole tick in one dispatch, on a CPU device one
/// dispatch per substep (see FusedShape). The fused tick keeps collision candidate lists with a
/// skin (SIM_CANDIDATE_* in sim_config.h) and rebuilds the hash only when a particle has travelled too
/// far for them; the sums, and so the results, are those of the hash search.
class GpuSolver final : public Solver, private PassSink {
public:
  /// A solver on an existing context (the renderer's); the context must outlive the solver.
  /// `fused` overrides the shape of the fused tick (the tests run a GPU's shape on lavapipe).
  explicit GpuSolver(VulkanContext& ctx, FusedShape fused = {});
  /// A solver that owns its context.
  explicit GpuSolver(std::unique_ptr<VulkanContext> ctx, FusedShape fused = {});
  ~GpuSolver() override;
  GpuSolver(const GpuSolver&) = delete;
  GpuSolver& operator=(const GpuSolver&) = delete;

  std::string name() const override { return "gpu"; }
  void upload(const SheetTopology& topo) override;
  int64_t contacts() const override;
  void tick(const shaderio::SimUniforms& u) override;
  void beginReset() override;
  void computeNormals() override;
  shaderio::PickResult pick(glm::vec3 o, glm::vec3 d, float radius) override;
  glm::vec3 particlePosition(uint32_t index) override;
  /// One submission copies every particle's position (the camera follow's samples each frame).
  std::vector<glm::vec3> particlePositions(const std::vector<uint32_t>& indices) override;
  void readback(SimState& out) override;
  PassTimes passTimes() const override;
  uint32_t dispatchesPerTick() const override { return dispatches_per_tick_; }
  uint32_t barrierPhasesPerTick() override;
  uint64_t memoryBytes() const override;
  Arithmetic arithmetic() const override;
  void stopNextTickAfter(uint32_t last_pass) override { stop_after_ = last_pass; }
  void readDeltas(std::vector<glm::vec4>& out) override;

  /// Times each dispatch of the per-colour passes apart, for passTimes().kernels: a timestamp
  /// after every one, which keeps the device from overlapping them (a profile, not a benchmark).
  void timeKernels(bool on);

  /// The context the solver runs on.
  VulkanContext& context() { return ctx_; }
  /// Buffers the renderer binds directly (vertex pulling or vertex/index input).
  VkBuffer positionBuffer() const { return buf_[SIM_BIND_POS].buffer; }
  VkBuffer normalBuffer() const { return buf_[SIM_BIND_NORMAL].buffer; }
  VkBuffer uvBuffer() const { return buf_[SIM_BIND_UV].buffer; }
  /// Live triangles: uvec4 (xyz vertices, w = triangle id); draw with counters' draw_args.
  VkBuffer triangleBuffer() const { return buf_[SIM_BIND_TRIANGLES].buffer; }
  /// shaderio::Counters; draw_args is a VkDrawIndirectCommand of 3 x live triangles.
  VkBuffer counterBuffer() const { return buf_[SIM_BIND_COUNTERS].buffer; }
  /// Byte offset of draw_args in the counter buffer.
  static constexpr VkDeviceSize kDrawArgsOffset = offsetof(shaderio::Counters, draw_args);
  /// Reads the spatial hash of the last substep (tests): bucket starts (T + 1) and particles (N).
  void readHash(std::vector<uint32_t>& cell_start, std::vector<uint32_t>& cell_particles);
  /// The buffer of a binding (SIM_BIND_*), for tests and tools.
  const Buffer& buffer(uint32_t binding) const { return buf_[binding]; }
  /// Allows (default) or forbids the fused small-sheet tick; it is used when allowed and the sheet
  /// fits it on this device (fusedTickFits).
  void setFusedPath(bool allowed) { fused_allowed_ = allowed; }
  /// True when the sheet is small enough for the fused small-sheet tick (and it is allowed).
  bool usesFusedPath() const;
  /// Invocations of the fused tick's workgroup (FusedShape::workgroup as resolved for the device).
  uint32_t fusedWorkgroup() const { return fused_workgroup_; }
  /// Keeps (default) or drops the collision candidate lists (SIM_CANDIDATE_* in sim_config.h); without
  /// them every substep with collision builds the hash and searches it. Lists are kept only when
  /// their buffer fits the device (one SIM_CANDIDATE_STRIDE record per particle).
  void setCandidateLists(bool keep) { candidates_allowed_ = keep; }
  /// True when ticks keep collision candidate lists.
  bool usesCandidateLists() const { return keepsCandidateLists(layout_sizes_, candidates_allowed_); }
  /// The pairs each contact query keeps in its list (SIM_CONTACT_LIST_CAPACITY, or fewer: the tests
  /// make queries overflow, which then search the grid every substep).
  void setContactListCapacity(uint32_t pairs) { contact_list_capacity_ = std::min(pairs, SIM_CONTACT_LIST_CAPACITY); }
  /// How many times the contact's pair lists have been built (0 before contact runs).
  uint32_t contactListBuilds();
  /// True when a tick with these uniforms runs the fused tick: the sheet is small enough, with
  /// collision on the hash cell is within the shape's limit, and with contact on the shape takes
  /// contact (FusedShape::contact).
  bool usesFusedPath(const shaderio::SimUniforms& u) const;
  /// Waits until every submitted tick has finished.
  void finish() override;

private:
  /// Tick command buffers in flight; each has its own uniforms, fence and timestamp pool.
  static constexpr uint32_t kInFlight = 2;
  /// Uniforms of the normals and pick passes (static: written at upload).
  static constexpr uint32_t kStaticUniforms = kInFlight;
  static constexpr uint32_t kBindingCount = kSheetBindingCount;
  struct RecordKey {
    uint32_t substeps = 0;
    bool fused = false;
    SubstepPlan plan; ///< what each substep runs (substepPlan), up to the pass it stops after
    bool operator==(const RecordKey&) const = default;
  };
  struct InFlight {
    VkCommandBuffer tick = VK_NULL_HANDLE, reset = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
    VkQueryPool queries = VK_NULL_HANDLE;
    bool pending = false; ///< submitted, fence not yet waited
    bool timed = false;   ///< the pending submission is a tick with timestamps
    std::optional<RecordKey> recorded;
    std::vector<uint8_t> categories; ///< category of each timestamp interval
    uint32_t dispatches = 0;
  };

  /// Where the sheet's bindings live: whole buffers.
  SheetPlace place() const;
  void createPipelines(FusedShape fused);
  void destroySheet();
  /// Sizes the contact's buffers (a sheet made with contact off has a word in each) and the
  /// scratch they share, once contact is turned on.
  void sizeContact();
  void writeStaticUniforms();
  /// Makes what the fused tick (`fused`) or the per-colour passes need that is not made yet, with
  /// `contact` or without.
  void makePathPipelines(bool fused, bool contact);
  void recordTick(InFlight& flight, uint32_t index, const RecordKey& key);
  // PassSink: the passes of the per-colour path go to the tick being recorded (recording_)
  void pass(const ComputePipeline& p, Grid grid, uint32_t count, const void* push, uint32_t push_size, uint32_t substep,
            const PassGate& gate) override;
  void barrier() override;
  void mark(PassCategory c) override;
  void recordReset(InFlight& flight, uint32_t index);
  void recordNormals();
  void bindSet(VkCommandBuffer cmd, uint32_t uniform_index);
  /// The one dispatch helper: binds the pipeline, checks and pushes the constants, and dispatches
  /// `count` elements (Threads), one workgroup (Workgroup), or the grid of an indirect argument
  /// (Compaction, Hash: the next hash dispatch's live arguments, whose full grid candidates_decide copies in;
  /// Sweep: those of the settle sweep `arg` names).
  void dispatch(VkCommandBuffer cmd, const ComputePipeline& p, Grid grid, uint32_t count, const void* push,
                uint32_t push_size, uint32_t arg = 0);
  template <class Push>
  void dispatch(VkCommandBuffer cmd, const ComputePipeline& p, Grid grid, uint32_t count, const Push& push) {
    dispatch(cmd, p, grid, count, &push, uint32_t(sizeof(Push)));
  }
  void timestamp(VkCommandBuffer cmd, InFlight& flight, PassCategory c);
  /// The query pools of the ticks in flight, sized for timeKernels when it is on
  void makeQueryPools();
  /// Pipeline p's kernel in SIM_KERNELS' order, or SIM_NONE for another pipeline
  uint32_t kernelOf(VkPipeline p) const;
  void waitFor(InFlight& flight) const;
  void collectTimes(const InFlight& flight) const;

  std::unique_ptr<VulkanContext> owned_ctx_;
  VulkanContext& ctx_;
  SheetTopology topo_;
  bool uploaded_ = false;

  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkDescriptorPool descriptor_pool_ = VK_NULL_HANDLE;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
  SimPipelines pipes_;
  InFlight* recording_ = nullptr; ///< the tick in flight being recorded

  std::array<Buffer, kBindingCount> buf_{};
  Buffer small_readback_; ///< host-visible: pick result and particle positions
  VkDeviceSize uniform_stride_ = 0;
  SheetLayout layout_sizes_; ///< sizes the passes and the bindings share

  mutable std::array<InFlight, kInFlight> in_flight_{};
  uint32_t next_in_flight_ = 0;
  int last_tick_ = -1;
  VkCommandBuffer normals_cmd_ = VK_NULL_HANDLE;
  VkFence normals_fence_ = VK_NULL_HANDLE;
  VkQueryPool normals_queries_ = VK_NULL_HANDLE;
  mutable bool normals_pending_ = false;
  bool last_contact_ = false; ///< the last tick had contact on
  uint32_t query_capacity_ = 0;
  uint32_t dispatches_per_tick_ = 0;
  bool fused_tick_ = false;           ///< the last tick ran fused (barrierPhasesPerTick)
  VkPipeline bound_ = VK_NULL_HANDLE; ///< pipeline bound while recording
  uint32_t recorded_dispatches_ = 0;
  bool fused_allowed_ = true;
  FloatRules float_rules_;                ///< what the shaders' SPIR-V asks of the device's float arithmetic
  MathSwitches math_;                     ///< the switches of exact_math.h (from the environment)
  uint32_t fused_workgroup_ = 0;          ///< invocations of the fused tick's workgroup (fusedWorkgroup)
  uint32_t fused_substeps_ = 1;           ///< substeps per dispatch of the fused tick
  float fused_max_cell_spacings_ = -1.0f; ///< largest hash cell of the fused tick (< 0: any)
  bool fused_contact_ = true;             ///< sheets with contact take the fused tick (FusedShape::contact)
  float spacing_ = 0.0f;                  ///< grid spacing: the shortest structural rest length
  bool candidates_allowed_ = true;        ///< setCandidateLists
  uint32_t contact_list_capacity_ = SIM_CONTACT_LIST_CAPACITY; ///< setContactListCapacity
  HashGrids hash_grids_;                                       ///< full grids of the hash passes, in recording order
  std::vector<glm::uvec4> hash_grids_uploaded_;                ///< what SIM_BIND_HASH_ARGS holds of them
  std::vector<glm::uvec4> contact_grids_uploaded_;             ///< ... and of contact's grid passes
  glm::uvec4 sweep_grid_uploaded_{0u};                         ///< ... and of a settle sweep
  uint32_t stop_after_ = SIM_NONE;                             ///< stopNextTickAfter
  mutable std::array<double, kCategoryCount> last_ms_{};
  bool time_kernels_ = false;
  /// Room for timeKernels' timestamps, one a dispatch
  static constexpr uint32_t kKernelTimestamps = 8192;
  /// The kernels' names in SIM_KERNELS' order; timeKernels' timestamps carry kCategoryCount + the index
  static constexpr const char* kKernelNames[] = {
#define SIM_KERNEL_NAME(name, push, per_invocation, batched) #name,
      SIM_KERNELS(SIM_KERNEL_NAME)
#undef SIM_KERNEL_NAME
  };
  static_assert(kCategoryCount + std::size(kKernelNames) <= 256, "a timestamp's category is a byte");
  /// The last timed tick's milliseconds and dispatches by kernel (SIM_KERNELS' order)
  mutable std::vector<std::pair<double, uint32_t>> last_kernel_ms_;
};

} // namespace tender::gpu
