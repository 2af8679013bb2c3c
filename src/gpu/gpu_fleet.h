#pragma once
/// A fleet of small sheets on Vulkan: each of the sheet's storage buffers holds a slice per sheet,
/// and one dispatch of tick_batch.comp runs the fused tick of every queued sheet, one workgroup
/// each, with its own uniforms (parameters, wind, grab). The shader reaches a sheet's slices by
/// device address from a table (SIM_BATCH_* in sim_config.h); its arithmetic is the fused tick's,
/// so sheet i ends bitwise where the same sheet run alone on the GPU ends.
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/fleet.h"
#include "gpu/context.h"
#include "gpu/sheet_buffers.h"
#include "gpu/sim_pipeline.h"

namespace tender::gpu {

class GpuFleet final : public SheetBatch {
public:
  /// A fleet of `sheets` sheets on an existing context (it must outlive the fleet). Throws with
  /// one line when the device cannot run it (no device addresses, too little shared memory).
  GpuFleet(VulkanContext& ctx, uint32_t sheets);
  /// A fleet that owns its context.
  GpuFleet(std::unique_ptr<VulkanContext> ctx, uint32_t sheets);
  ~GpuFleet() override;
  GpuFleet(const GpuFleet&) = delete;
  GpuFleet& operator=(const GpuFleet&) = delete;

  /// Why sheets of these parameters cannot join a fleet (more than SIM_FUSED_MAX_PARTICLES
  /// particles or SIM_FUSED_MAX_BUCKETS buckets; with collision, a hash cell over
  /// SIM_FUSED_CPU_MAX_CELL_SPACINGS spacings, which a CPU device's fused tick does not take);
  /// nullopt when they can.
  static std::optional<std::string> fits(const SimParams& params);

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

  void create(uint32_t sheets);
  /// Allocates every buffer for the fleet from the first sheet's topology.
  void allocate(const SheetTopology& topo);
  void uploadSheet(uint32_t i, const SheetTopology& topo);
  void resetSheet(uint32_t i);
  void readSheet(uint32_t i, SimState& out);
  glm::vec4 readParticle(uint32_t i, uint32_t particle);
  std::vector<glm::vec4> readSheetPositions(uint32_t i);
  void readSheetDeltas(uint32_t i, std::vector<glm::vec4>& out);
  /// Copies `bytes` of each (binding, sheet) slice listed into one host buffer; returns it.
  Buffer download(const std::vector<std::pair<uint32_t, VkDeviceSize>>& slices, uint32_t sheet,
                  std::vector<VkDeviceSize>& offsets);
  /// Records the start contents of sheet i's slices of the table's bindings (those a reset restores).
  void stage(VkCommandBuffer cmd, uint32_t i, const std::vector<BindingSpec>& table, bool restored_only,
             Buffer& staging);
  VkDeviceSize sliceOffset(uint32_t binding, uint32_t sheet) const { return stride_[binding] * sheet; }

  std::unique_ptr<VulkanContext> owned_ctx_;
  VulkanContext& ctx_;
  std::vector<std::unique_ptr<Sheet>> sheets_;
  std::vector<std::unique_ptr<QueuedSolver>> queued_;

  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  VkShaderModule module_ = VK_NULL_HANDLE;
  FloatRules float_rules_;
  MathSwitches math_;
  uint32_t substeps_per_dispatch_ = 1;
  uint32_t sheets_per_group_ = 1; ///< sheets a dispatch of a CPU device takes (a substep each)

  SheetTopology topo_; ///< the topology every sheet shares
  SheetLayout sizes_;
  bool allocated_ = false;
  std::array<Buffer, SIM_BATCH_ENTRIES> buf_{};          ///< per binding: a slice per sheet; the queue
  std::array<VkDeviceSize, SIM_BATCH_ENTRIES> stride_{}; ///< bytes from one sheet's slice to the next
  Buffer table_;                                         ///< SIM_BATCH_ENTRIES uvec4 (device)
  Buffer inputs_;                                        ///< host: the queue, then the uniforms of each sheet

  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  bool pending_ = false;
  uint32_t last_dispatches_ = 0;
};

} // namespace tender::gpu
