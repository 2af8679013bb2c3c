// GpuBatch, a fleet of sheets in slices of shared buffers: its creation, its allocation when the
// first sheet is made, and the passes it records (gpu_batch_flush.cpp records and submits a
// flush; gpu_batch_io.cpp holds the transfers).
#include "gpu_batch.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>
#include <thread>

#include "core/host_queries.h"
#include "gpu/barriers.h"
#include "gpu/gpu_solver.h"

namespace tender::gpu {

using namespace shaderio;

namespace {

constexpr VkBufferUsageFlags kSliceUsage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                           VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;

} // namespace

/// Sheet i of the batch as a Solver: uploads, resets and read-backs of its slices. Its ticks never
/// come here: the QueuedSolver queues them and the batch runs them all in one dispatch.
class GpuBatch::Sheet final : public Solver {
public:
  Sheet(GpuBatch& batch, uint32_t index) : batch_(batch), index_(index) {}
  std::string name() const override { return "gpu"; }
  void upload(const SheetTopology& topo) override { batch_.uploadSheet(index_, topo); }
  void tick(const SimUniforms&) override { throw std::logic_error("a fleet's sheet ticks through its batch"); }
  void beginReset() override { batch_.resetSheet(index_); }
  /// The normals are computed from the positions when the state is read back.
  void computeNormals() override {}
  PickResult pick(glm::vec3 o, glm::vec3 d, float radius) override {
    return pickNearest(batch_.readSheetPositions(index_), o, d, radius);
  }
  glm::vec3 particlePosition(uint32_t index) override { return glm::vec3(batch_.readParticle(index_, index)); }
  void readback(SimState& out) override { batch_.readSheet(index_, out); }
  void finish() override { batch_.finish(); }
  uint32_t dispatchesPerTick() const override { return batch_.last_dispatches_; }
  int64_t contacts() const override { return batch_.sheetContacts(index_); }
  uint64_t memoryBytes() const override { return batch_.memoryBytes() / std::max<uint32_t>(batch_.size(), 1); }
  Arithmetic arithmetic() const override { return arithmeticOf(batch_.float_rules_, batch_.math_); }
  void stopNextTickAfter(uint32_t last_pass) override {
    if (last_pass != SIM_NONE) throw std::runtime_error("a fleet runs whole ticks (tender diff runs one sheet)");
  }
  void readDeltas(std::vector<glm::vec4>& out) override { batch_.readSheetDeltas(index_, out); }

private:
  GpuBatch& batch_;
  uint32_t index_;
};

GpuBatch::GpuBatch(VulkanContext& ctx, uint32_t sheets, BatchPasses passes, FusedShape fused) : ctx_(ctx) {
  create(sheets, passes, fused);
}

GpuBatch::GpuBatch(std::unique_ptr<VulkanContext> ctx, uint32_t sheets, FusedShape fused)
    : owned_ctx_(std::move(ctx)), ctx_(*owned_ctx_) {
  create(sheets, BatchPasses::Auto, fused);
}

void GpuBatch::create(uint32_t sheets, BatchPasses passes, FusedShape fused) {
  // A sheet per workgroup: x of the fused tick's grid, z of a pass's
  const uint32_t most = std::min(ctx_.properties().limits.maxComputeWorkGroupCount[0],
                                 ctx_.properties().limits.maxComputeWorkGroupCount[2]);
  if (sheets == 0 || sheets > most)
    throw std::runtime_error("a GPU fleet runs 1 to " + std::to_string(most) + " sheets per batch, not " +
                             std::to_string(sheets));
  if (!ctx_.deviceAddresses())
    throw std::runtime_error("Vulkan device " + ctx_.info().name +
                             " cannot run a fleet: it lacks bufferDeviceAddress or shaderInt64 (try --backend cpu)");
  VkDevice dev = ctx_.device();
  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, uint32_t(sizeof(BatchPush))};
  static_assert(sizeof(BatchPush) == sizeof(BatchPassPush));
  VkPipelineLayoutCreateInfo pli{};
  pli.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  pli.pushConstantRangeCount = 1;
  pli.pPushConstantRanges = &range;
  VK_CHECK(vkCreatePipelineLayout(dev, &pli, nullptr, &layout_));
  float_rules_ = simFloatRules(ctx_);
  math_ = MathSwitches::fromEnvironment();
  // The fused tick's shape on this kind of device (see FusedShape in gpu_solver.h); a sheet larger
  // than its capacity (fusedCapacity) runs the per-colour passes, as it does alone.
  const bool cpu_device = ctx_.properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
  const FusedShape shape = resolveFusedShape(ctx_, fused, true);
  substeps_per_dispatch_ = shape.substeps_per_dispatch;
  fused_workgroup_ = shape.workgroup;
  fused_contact_ = shape.contact > 0;
  fused_max_cell_spacings_ = shape.max_cell_spacings;
  sheets_per_group_ = std::max(1u, std::thread::hardware_concurrency()) * SIM_BATCH_CPU_SHEETS_PER_THREAD;
  per_sheet_ = passes == BatchPasses::PerSheet || (passes == BatchPasses::Auto && cpu_device);
  // The batched passes, or each sheet's (below): only those this batch records
  if (!per_sheet_) passes_ = makePassPipelines(ctx_, {layout_, "batch"}, float_rules_, math_, true);
  {
    // The layouts of one sheet's passes at a time (per_sheet_)
    sheet_set_layout_ = createSheetSetLayout(dev);
    VkPushConstantRange sheet_range{VK_SHADER_STAGE_COMPUTE_BIT, 0, uint32_t(sizeof(SimPush))};
    pli.setLayoutCount = 1;
    pli.pSetLayouts = &sheet_set_layout_;
    pli.pPushConstantRanges = &sheet_range;
    VK_CHECK(vkCreatePipelineLayout(dev, &pli, nullptr, &sheet_layout_));
    if (per_sheet_) sheet_passes_ = makePassPipelines(ctx_, {sheet_layout_, "sheet"}, float_rules_, math_, false);
  }

  VkFenceCreateInfo fci{};
  fci.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
  VK_CHECK(vkCreateFence(dev, &fci, nullptr, &fence_));
  VkCommandBufferAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  ai.commandPool = ctx_.commandPool();
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VK_CHECK(vkAllocateCommandBuffers(dev, &ai, &cmd_));

  sheets_.reserve(sheets);
  queued_.reserve(sheets);
  contact_on_.assign(sheets, false);
  for (uint32_t i = 0; i < sheets; ++i) {
    sheets_.push_back(std::make_unique<Sheet>(*this, i));
    queued_.push_back(std::make_unique<QueuedSolver>(*this, *sheets_.back()));
  }
}

void GpuBatch::releaseSlices() {
  VkDevice dev = ctx_.device();
  vkDeviceWaitIdle(dev);
  for (Buffer& b : buf_) ctx_.destroyBuffer(b);
  ctx_.destroyBuffer(table_);
  ctx_.destroyBuffer(inputs_);
  if (sheet_pool_) vkDestroyDescriptorPool(dev, sheet_pool_, nullptr);
  sheet_pool_ = VK_NULL_HANDLE;
  sheet_sets_.clear();
  allocated_ = false;
}

GpuBatch::~GpuBatch() {
  VkDevice dev = ctx_.device();
  vkDeviceWaitIdle(dev);
  for (Buffer& b : buf_) ctx_.destroyBuffer(b);
  ctx_.destroyBuffer(table_);
  ctx_.destroyBuffer(inputs_);
  if (cmd_) vkFreeCommandBuffers(dev, ctx_.commandPool(), 1, &cmd_);
  if (fence_) vkDestroyFence(dev, fence_, nullptr);
  if (sheet_pool_) vkDestroyDescriptorPool(dev, sheet_pool_, nullptr);
  if (sheet_layout_) vkDestroyPipelineLayout(dev, sheet_layout_, nullptr);
  if (sheet_set_layout_) vkDestroyDescriptorSetLayout(dev, sheet_set_layout_, nullptr);
  if (layout_) vkDestroyPipelineLayout(dev, layout_, nullptr);
}

void GpuBatch::allocate(const SheetTopology& topo) {
  topo_ = topo;
  spacing_ = structuralSpacing(topo);
  sizes_ = SheetLayout::of(topo, ctx_.properties().limits.maxStorageBufferRange, topo.contact);
  const uint32_t sheets = size();
  StartData start;
  const std::vector<BindingSpec> table = sheetBindings(topo_, sizes_, start, false);
  // A slice per sheet in each binding's buffer; the uniforms as one binding more.
  stride_[SIM_BIND_UNIFORMS] = alignUp(sizeof(SimUniforms), kSliceAlign);
  for (const BindingSpec& b : table) stride_[b.binding] = alignUp(std::max<VkDeviceSize>(b.bytes, 16), kSliceAlign);
  stride_[SIM_BATCH_QUEUE] = stride_[SIM_BATCH_ARGS] = 0;
  std::array<glm::uvec4, SIM_BATCH_ENTRIES> entries{};
  try {
    for (uint32_t b = 0; b < SIM_BATCH_ENTRIES; ++b) {
      const VkDeviceSize bytes = b == SIM_BATCH_QUEUE  ? 4ull * sheets
                                 : b == SIM_BATCH_ARGS ? kArgsBytes
                                                       : stride_[b] * sheets;
      if (bytes == 0) continue;
      // Indirect arguments: the batch's, and (PerSheet) each sheet's counters and hash arguments
      const bool indirect = b == SIM_BATCH_ARGS || b == SIM_BIND_COUNTERS || b == SIM_BIND_HASH_ARGS;
      VkBufferUsageFlags usage = kSliceUsage;
      if (indirect) usage |= VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT;
      if (b == SIM_BIND_UNIFORMS) usage |= VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT;
      buf_[b] = ctx_.createDeviceBuffer(bytes, usage);
      const VkDeviceAddress a = ctx_.address(buf_[b]);
      entries[b] = glm::uvec4(uint32_t(a), uint32_t(a >> 32), uint32_t(stride_[b]), uint32_t(stride_[b] >> 32));
    }
    table_ = ctx_.createDeviceBuffer(sizeof(entries), kSliceUsage);
    table_address_ = ctx_.address(table_);
    inputs_ =
        ctx_.createHostBuffer(alignUp(4ull * sheets, kSliceAlign) + stride_[SIM_BIND_UNIFORMS] * sheets + kArgsBytes,
                              VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  } catch (const VulkanError&) {
    for (Buffer& b : buf_) ctx_.destroyBuffer(b);
    ctx_.destroyBuffer(table_);
    throw std::runtime_error("a batch of " + std::to_string(sheets) + " " + std::to_string(topo.cols) + "x" +
                             std::to_string(topo.rows) + " sheets does not fit the memory of Vulkan device " +
                             ctx_.info().name + " (try a smaller --batch)");
  }
  ctx_.submitOnce([&](VkCommandBuffer cmd) { vkCmdUpdateBuffer(cmd, table_.buffer, 0, sizeof(entries), &entries); });
  if (per_sheet_) {
    // Each sheet's descriptor set over its slices
    VkDevice dev = ctx_.device();
    sheet_pool_ = createSheetSetPool(dev, sheets);
    sheet_sets_ = allocateDescriptorSets(dev, sheet_pool_, sheet_set_layout_, sheets);
    for (uint32_t i = 0; i < sheets; ++i) {
      std::array<VkDescriptorBufferInfo, kSheetBindingCount> where{};
      for (uint32_t b = 0; b < kSheetBindingCount; ++b)
        where[b] = {buf_[b].buffer, sliceOffset(b, i), b == SIM_BIND_UNIFORMS ? sizeof(SimUniforms) : stride_[b]};
      writeSheetSet(dev, sheet_sets_[i], where);
    }
  }
  allocated_ = true;
}

void GpuBatch::finish() {
  if (!pending_) return;
  VK_CHECK(vkWaitForFences(ctx_.device(), 1, &fence_, VK_TRUE, UINT64_MAX));
  pending_ = false;
}

void GpuBatch::pass(const ComputePipeline& p, Grid grid, uint32_t count, const void* push, uint32_t push_size,
                    uint32_t substep, const PassGate& gate) {
  if (pass_sheet_ >= 0) {
    passOfSheet(uint32_t(pass_sheet_), p, grid, count, push, push_size, gate.arg);
    return;
  }
  if (push_size > sizeof(SimPush) || p.push_size != sizeof(BatchPassPush))
    vkCheckFailed(VK_ERROR_UNKNOWN, "push constant size", __FILE__, __LINE__);
  // The grid a sheet alone gets, with a workgroup z per sheet: from the element count; the hash
  // passes, the compaction and contact's indirect passes from the batch's live arguments, which
  // the sheets that need them arm (the gates skip the other sheets).
  const bool counted = grid == Grid::Threads || grid == Grid::Hash || grid == Grid::Contact || grid == Grid::Settle ||
                       grid == Grid::Sweep;
  if ((counted || grid == Grid::Walk || grid == Grid::Cross || grid == Grid::Named) && count == 0) return;
  const glm::uvec4 full = fullGrid(p, counted ? count : 1u, pass_sheets_);
  const uint32_t hash_dispatch = hash_grids_.record(grid, full, gate.arg);
  BatchPassPush bp{};
  if (push_size) std::memcpy(&bp.pass, push, push_size);
  const VkDeviceAddress table = table_address_;
  bp.batch.table = glm::uvec2(uint32_t(table), uint32_t(table >> 32));
  bp.batch.first = pass_first_;
  bp.batch.substep = substep;
  bp.batch.when = gate.when;
  bp.batch.live = gate.live;
  bp.batch.arg = gate.arg;
  if (bound_ != p.pipeline) {
    vkCmdBindPipeline(cmd_, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
    bound_ = p.pipeline;
  }
  vkCmdPushConstants(cmd_, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(bp), &bp);
  switch (grid) {
  case Grid::Threads:
    vkCmdDispatch(cmd_, full.x, full.y, pass_sheets_);
    break;
  case Grid::Workgroup:
    vkCmdDispatch(cmd_, 1, 1, pass_sheets_);
    break;
  case Grid::Hash:
    vkCmdDispatchIndirect(cmd_, buf_[SIM_BATCH_ARGS].buffer,
                          16ull * (SIM_BATCH_ARGS_LIVE_HASH + substep * SIM_HASH_DISPATCHES + hash_dispatch));
    break;
  case Grid::Compaction:
    vkCmdDispatchIndirect(cmd_, buf_[SIM_BATCH_ARGS].buffer, 16ull * (SIM_BATCH_ARGS_LIVE_COMPACT + substep));
    break;
  case Grid::Contact:
  case Grid::Walk:
  case Grid::Cross:
  case Grid::Named: {
    // Contact's: its grid's pass k (hash_dispatch names the sheet's own slot), contact_walk,
    // contact_cross, the named queries
    const uint32_t slot = grid == Grid::Contact ? hash_dispatch - SIM_CONTACT_GRID_ARGS
                          : grid == Grid::Walk  ? SIM_CONTACT_GRID_DISPATCHES
                          : grid == Grid::Cross ? SIM_CONTACT_GRID_DISPATCHES + 1
                                                : SIM_CONTACT_GRID_DISPATCHES + 2;
    vkCmdDispatchIndirect(cmd_, buf_[SIM_BATCH_ARGS].buffer,
                          16ull * (SIM_BATCH_ARGS_LIVE_CONTACT + substep * SIM_BATCH_CONTACT_SLOTS + slot));
    break;
  }
  case Grid::Settle:
  case Grid::Sweep: // the settle's slot (hash_dispatch names the sheet's own)
    vkCmdDispatchIndirect(cmd_, buf_[SIM_BATCH_ARGS].buffer,
                          16ull * (SIM_BATCH_ARGS_LIVE_SETTLE + substep * SIM_CONTACT_SETTLE_SLOTS + hash_dispatch -
                                   SIM_CONTACT_SETTLE_ARGS));
    break;
  }
  ++last_dispatches_;
}

void GpuBatch::passOfSheet(uint32_t i, const ComputePipeline& p, Grid grid, uint32_t count, const void* push,
                           uint32_t push_size, uint32_t arg) {
  const SheetPassTarget target{cmd_,
                               sheet_layout_,
                               buf_[SIM_BIND_HASH_ARGS].buffer,
                               sliceOffset(SIM_BIND_HASH_ARGS, i),
                               buf_[SIM_BIND_COUNTERS].buffer,
                               sliceOffset(SIM_BIND_COUNTERS, i)};
  if (recordSheetPass(target, bound_, hash_grids_, p, grid, count, push, push_size, arg)) ++last_dispatches_;
}

void GpuBatch::barrier() { computeToCompute(cmd_); }

uint64_t GpuBatch::memoryBytes() const {
  uint64_t total = table_.size + inputs_.size;
  for (const Buffer& b : buf_) total += b.size;
  return total;
}

} // namespace tender::gpu
