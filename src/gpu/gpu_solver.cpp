#include "gpu_solver.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "gpu/barriers.h"
#include "gpu/shaders.h"

namespace tender::gpu {

using namespace shaderio;

static_assert(sizeof(ScanPush) == 16);
static_assert(sizeof(PickPush) == 48);

namespace {

/// Usage of every simulation buffer: storage, copies, and the renderer's vertex/index/indirect reads.
constexpr VkBufferUsageFlags kStorageUsage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                             VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_VERTEX_BUFFER_BIT |
                                             VK_BUFFER_USAGE_INDEX_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT;

Counters initialCounters(uint32_t triangles) {
  Counters c{};
  c.triangle_count = triangles;
  c.compact_dispatch = uvec4(0u, 1u, 1u, 0u);
  c.draw_args = uvec4(3u * triangles, 1u, 0u, 0u);
  return c;
}

/// The adjacency of each particle as a mask over its 5 x 5 grid stencil (SIM_BIND_ADJ_MASK), so
/// that the collision gather tests a neighbour with a bit instead of a search.
std::vector<uint32_t> adjacencyMasks(const SheetTopology& topo) {
  constexpr int kReach = SIM_ADJ_STENCIL;
  std::vector<uint32_t> masks(topo.particleCount(), 0u);
  for (uint32_t i = 0; i < masks.size(); ++i)
    for (uint32_t k = topo.adj_offsets[i]; k < topo.adj_offsets[i + 1]; ++k) {
      const uint32_t j = topo.adj_list[k];
      const int dx = int(j % topo.cols) - int(i % topo.cols), dy = int(j / topo.cols) - int(i / topo.cols);
      if (std::abs(dx) <= kReach && std::abs(dy) <= kReach)
        masks[i] |= 1u << uint32_t((dy + kReach) * (2 * kReach + 1) + dx + kReach);
      else
        masks[i] |= SIM_ADJ_FAR;
    }
  return masks;
}

} // namespace

GpuSolver::GpuSolver(std::unique_ptr<VulkanContext> ctx) : owned_ctx_(std::move(ctx)), ctx_(*owned_ctx_) {
  createPipelines({});
}

GpuSolver::GpuSolver(VulkanContext& ctx, FusedShape fused) : ctx_(ctx) { createPipelines(fused); }

GpuSolver::~GpuSolver() {
  VkDevice dev = ctx_.device();
  vkDeviceWaitIdle(dev);
  destroySheet();
  for (Slot& s : slots_) {
    if (s.fence) vkDestroyFence(dev, s.fence, nullptr);
    if (s.queries) vkDestroyQueryPool(dev, s.queries, nullptr);
  }
  if (normals_fence_) vkDestroyFence(dev, normals_fence_, nullptr);
  if (normals_queries_) vkDestroyQueryPool(dev, normals_queries_, nullptr);
  ctx_.destroyBuffer(small_readback_);
  auto destroy = [&](ComputePipeline& p) {
    if (p.pipeline) vkDestroyPipeline(dev, p.pipeline, nullptr);
  };
  for (ComputePipeline* p :
       {&pipes_.integrate,    &pipes_.project,   &pipes_.hash_count, &pipes_.scan,       &pipes_.scan_add,
        &pipes_.hash_scatter, &pipes_.hash_sort, &pipes_.collide,    &pipes_.near_check, &pipes_.near_finish,
        &pipes_.near_decide,  &pipes_.floor,     &pipes_.tear_mark,  &pipes_.tear_flags, &pipes_.tear_compact,
        &pipes_.normals,      &pipes_.reset,     &pipes_.tick_fused, &pipes_.pick[0],    &pipes_.pick[1],
        &pipes_.pick[2]})
    destroy(*p);
  for (VkShaderModule m : modules_) vkDestroyShaderModule(dev, m, nullptr);
  if (layout_) vkDestroyPipelineLayout(dev, layout_, nullptr);
  if (set_layout_) vkDestroyDescriptorSetLayout(dev, set_layout_, nullptr);
}

void GpuSolver::createPipelines(FusedShape fused) {
  VkDevice dev = ctx_.device();
  // One set layout: the uniforms (dynamic offset per tick slot) and every storage array.
  std::vector<VkDescriptorSetLayoutBinding> bindings(kBindingCount);
  for (uint32_t b = 0; b < kBindingCount; ++b) {
    bindings[b].binding = b;
    bindings[b].descriptorType =
        b == SIM_BIND_UNIFORMS ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    bindings[b].descriptorCount = 1;
    bindings[b].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  }
  VkDescriptorSetLayoutCreateInfo sli{};
  sli.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  sli.bindingCount = kBindingCount;
  sli.pBindings = bindings.data();
  VK_CHECK(vkCreateDescriptorSetLayout(dev, &sli, nullptr, &set_layout_));
  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, uint32_t(sizeof(PickPush))};
  VkPipelineLayoutCreateInfo pli{};
  pli.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  pli.setLayoutCount = 1;
  pli.pSetLayouts = &set_layout_;
  pli.pushConstantRangeCount = 1;
  pli.pPushConstantRanges = &range;
  VK_CHECK(vkCreatePipelineLayout(dev, &pli, nullptr, &layout_));

  // spec: specialization constant 0 when >= 0 (the step of a pick pass, the fused tick's workgroup size)
  auto make = [&](const char* key, uint32_t push_size, uint32_t workgroup, int spec = -1) {
    std::span<const uint32_t> code = simShader(key);
    if (code.empty()) vkCheckFailed(VK_ERROR_INITIALIZATION_FAILED, key, __FILE__, __LINE__);
    VkShaderModuleCreateInfo mi{};
    mi.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    mi.codeSize = code.size_bytes();
    mi.pCode = code.data();
    VkShaderModule module;
    VK_CHECK(vkCreateShaderModule(dev, &mi, nullptr, &module));
    modules_.push_back(module);
    uint32_t spec_value = spec < 0 ? 0u : uint32_t(spec);
    VkSpecializationMapEntry entry{0, 0, sizeof(uint32_t)};
    VkSpecializationInfo spec_info{1, &entry, sizeof(uint32_t), &spec_value};
    VkComputePipelineCreateInfo ci{};
    ci.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    ci.stage = {};
    ci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = module;
    ci.stage.pName = "main";
    ci.stage.pSpecializationInfo = spec >= 0 ? &spec_info : nullptr;
    ci.layout = layout_;
    ComputePipeline p;
    VK_CHECK(vkCreateComputePipelines(dev, VK_NULL_HANDLE, 1, &ci, nullptr, &p.pipeline));
    p.push_size = push_size;
    p.workgroup = workgroup;
    return p;
  };
  constexpr uint32_t kSim = sizeof(SimPush), kScan = sizeof(ScanPush), kPick = sizeof(PickPush);
  pipes_.integrate = make("integrate.comp", kSim, SIM_WG_PARTICLES);
  pipes_.project = make("project.comp", kSim, SIM_WG_PROJECT);
  pipes_.hash_count = make("hash_count.comp", kSim, SIM_WG_PARTICLES);
  pipes_.scan = make("scan.comp", kScan, SIM_SCAN_BLOCK); // one workgroup per block of elements
  pipes_.scan_add = make("scan_add.comp", kScan, SIM_WG_TEAR);
  pipes_.hash_scatter = make("hash_scatter.comp", kSim, SIM_WG_PARTICLES);
  pipes_.hash_sort = make("hash_sort.comp", kSim, SIM_WG_PARTICLES);
  pipes_.collide = make("collide.comp", kSim, SIM_WG_COLLIDE);
  pipes_.near_check = make("near_check.comp", kSim, SIM_WG_PARTICLES);
  pipes_.near_finish = make("near_finish.comp", kSim, 1);
  pipes_.near_decide = make("near_decide.comp", kSim, 1);
  pipes_.floor = make("floor.comp", kSim, SIM_WG_PARTICLES);
  pipes_.tear_mark = make("tear_mark.comp", kSim, SIM_WG_TEAR);
  pipes_.tear_flags = make("tear_flags.comp", 0, SIM_WG_TEAR);
  pipes_.tear_compact = make("tear_compact.comp", 0, SIM_WG_TEAR);
  pipes_.normals = make("normals.comp", kSim, SIM_WG_PARTICLES);
  pipes_.reset = make("reset.comp", kSim, SIM_WG_PARTICLES);
  // The fused tick keeps the positions in shared memory; its shape suits the device.
  const bool cpu_device = ctx_.properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
  uint32_t fused_workgroup = fused.workgroup ? fused.workgroup : cpu_device ? SIM_WG_FUSED_CPU : SIM_WG_FUSED;
  fused_workgroup = std::min(fused_workgroup, uint32_t(SIM_WG_FUSED));
  fused_substeps_ = fused.substeps_per_dispatch ? fused.substeps_per_dispatch
                    : cpu_device                ? SIM_FUSED_SUBSTEPS_CPU
                                                : SIM_MAX_SUBSTEPS;
  fused_max_cell_spacings_ = fused.max_cell_spacings != 0.0f ? fused.max_cell_spacings
                             : cpu_device                    ? SIM_FUSED_CPU_MAX_CELL_SPACINGS
                                                             : -1.0f;
  if (ctx_.properties().limits.maxComputeSharedMemorySize >= 16u * SIM_FUSED_MAX_PARTICLES)
    pipes_.tick_fused = make("tick_fused.comp", kSim, fused_workgroup, int(fused_workgroup));
  for (int s = 0; s < 3; ++s) pipes_.pick[size_t(s)] = make("pick.comp", kPick, SIM_WG_PARTICLES, s);

  // Per-slot fences and timestamp pools (chain of timestamps at pass boundaries).
  query_capacity_ = 2 + 6 * SIM_MAX_SUBSTEPS;
  VkFenceCreateInfo fci{};
  fci.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
  VkQueryPoolCreateInfo qci{};
  qci.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
  qci.queryType = VK_QUERY_TYPE_TIMESTAMP;
  for (Slot& s : slots_) {
    VK_CHECK(vkCreateFence(dev, &fci, nullptr, &s.fence));
    if (ctx_.timestampsSupported()) {
      qci.queryCount = query_capacity_;
      VK_CHECK(vkCreateQueryPool(dev, &qci, nullptr, &s.queries));
    }
  }
  VK_CHECK(vkCreateFence(dev, &fci, nullptr, &normals_fence_));
  if (ctx_.timestampsSupported()) {
    qci.queryCount = 2;
    VK_CHECK(vkCreateQueryPool(dev, &qci, nullptr, &normals_queries_));
  }
  small_readback_ = ctx_.createHostBuffer(64, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
}

uint32_t GpuSolver::scanSumsSize(uint32_t count) {
  uint32_t groups = (count + SIM_SCAN_BLOCK - 1) / SIM_SCAN_BLOCK;
  return groups + (groups > 1 ? scanSumsSize(groups) : 0);
}

void GpuSolver::destroySheet() {
  VkDevice dev = ctx_.device();
  for (Slot& s : slots_) {
    VkCommandBuffer cmds[2] = {s.tick, s.reset};
    if (s.tick) vkFreeCommandBuffers(dev, ctx_.commandPool(), 2, cmds);
    s.tick = s.reset = VK_NULL_HANDLE;
    s.pending = s.timed = false;
    s.recorded.reset();
  }
  if (normals_cmd_) vkFreeCommandBuffers(dev, ctx_.commandPool(), 1, &normals_cmd_);
  normals_cmd_ = VK_NULL_HANDLE;
  normals_pending_ = false;
  if (descriptor_pool_) vkDestroyDescriptorPool(dev, descriptor_pool_, nullptr);
  descriptor_pool_ = VK_NULL_HANDLE;
  set_ = VK_NULL_HANDLE;
  for (Buffer& b : buf_) ctx_.destroyBuffer(b);
  last_tick_slot_ = -1;
  uploaded_ = false;
}

void GpuSolver::upload(const SheetTopology& topo) {
  VkDevice dev = ctx_.device();
  VK_CHECK(vkDeviceWaitIdle(dev));
  destroySheet();
  topo_ = topo;
  spacing_ = std::numeric_limits<float>::max();
  for (const Constraint& k : topo.constraints)
    if ((k.kind_id & SIM_KIND_MASK) == SIM_KIND_STRUCTURAL) spacing_ = std::min(spacing_, k.rest);
  const uint32_t n = topo.particleCount(), m = topo.constraintCount(), t = topo.triangleCount();
  const uint32_t cells = topo.hash_size;
  tear_slots_ = m + t + 1;
  tear_sums_ = tear_slots_;
  hash_sums_ = tear_sums_ + scanSumsSize(tear_slots_);
  // The fused tick's scans meet their per-invocation totals in the SIM_WG_FUSED slots after the
  // compaction slots (the separate passes' block sums, unused on that path).
  const uint32_t scratch_size = std::max(hash_sums_ + scanSumsSize(cells), tear_slots_ + SIM_WG_FUSED);

  // Buffers of DESIGN.md §2, sized from the topology.
  VkDeviceSize align = ctx_.properties().limits.minUniformBufferOffsetAlignment;
  uniform_stride_ = (sizeof(SimUniforms) + align - 1) / align * align;
  buf_[SIM_BIND_UNIFORMS] = ctx_.createHostBuffer(uniform_stride_ * (kSlots + 1), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  // A sheet whose arrays exceed what the device binds is refused with one line, not left to fail
  const VkDeviceSize max_range = ctx_.properties().limits.maxStorageBufferRange;
  auto storage = [&](uint32_t binding, VkDeviceSize bytes) {
    if (bytes > max_range)
      throw std::runtime_error("a " + std::to_string(topo.cols) + "x" + std::to_string(topo.rows) + " sheet needs a " +
                               std::to_string(bytes >> 20) + " MiB buffer (binding " + std::to_string(binding) +
                               "); this Vulkan device binds at most " + std::to_string(max_range >> 20) +
                               " MiB (try a smaller sheet or --backend cpu)");
    buf_[binding] = ctx_.createDeviceBuffer(bytes, kStorageUsage);
  };
  storage(SIM_BIND_POS, 16ull * n);
  storage(SIM_BIND_PREV, 16ull * n);
  storage(SIM_BIND_REST, 16ull * n);
  storage(SIM_BIND_UV, 8ull * n);
  storage(SIM_BIND_NORMAL, 16ull * n);
  storage(SIM_BIND_CONSTRAINTS, 16ull * m);
  storage(SIM_BIND_COLOR_RANGES, 8ull * topo.colorCount());
  storage(SIM_BIND_ADJ_OFFSETS, 4ull * topo.adj_offsets.size());
  storage(SIM_BIND_ADJ_LIST, 4ull * topo.adj_list.size());
  storage(SIM_BIND_CELL_COUNT, 4ull * cells);
  storage(SIM_BIND_CELL_START, 4ull * (cells + 1));
  storage(SIM_BIND_CELL_PARTICLES, 4ull * n);
  storage(SIM_BIND_PARTICLE_CELL, 4ull * n);
  storage(SIM_BIND_DELTA, 16ull * n);
  storage(SIM_BIND_TORN, 4ull * m);
  storage(SIM_BIND_TRIANGLES, 16ull * t);
  storage(SIM_BIND_TRI_EDGES, 8ull * topo.tri_edges.size());
  storage(SIM_BIND_COUNTERS, sizeof(Counters));
  storage(SIM_BIND_SCRATCH, 4ull * scratch_size);
  storage(SIM_BIND_PICK, sizeof(PickResult));
  storage(SIM_BIND_RESET_FROM, 16ull * n);
  storage(SIM_BIND_CELL_SCATTER, 4ull * n);
  storage(SIM_BIND_COMPACT_TMP, 16ull * (m + t));
  storage(SIM_BIND_CELL_POS, 16ull * n);
  storage(SIM_BIND_ADJ_MASK, 4ull * n);
  // Collision candidate lists, when the largest binding holds them
  const VkDeviceSize list_bytes = 4ull * SIM_NEAR_STRIDE * n;
  lists_fit_ = list_bytes <= ctx_.properties().limits.maxStorageBufferRange;
  storage(SIM_BIND_NEAR, lists_fit_ ? list_bytes : 16);
  storage(SIM_BIND_NEAR_BASE, lists_fit_ ? 16ull * n : 16);
  storage(SIM_BIND_HASH_ARGS, 16ull * 2 * SIM_HASH_DISPATCHES);
  hash_grids_.clear();
  hash_grids_uploaded_.clear();

  // Start state and the static arrays, in one submission.
  std::vector<Buffer> staging;
  auto stage = [&](uint32_t binding, const void* data, VkDeviceSize bytes, VkCommandBuffer cmd, VkDeviceSize dst = 0) {
    if (bytes == 0) return;
    Buffer s = ctx_.createHostBuffer(bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    std::memcpy(s.mapped, data, size_t(bytes));
    VkBufferCopy region{0, dst, bytes};
    vkCmdCopyBuffer(cmd, s.buffer, buf_[binding].buffer, 1, &region);
    staging.push_back(s);
  };
  std::vector<uint32_t> last_start = {n};
  ctx_.submitOnce([&](VkCommandBuffer cmd) {
    for (Buffer& b : buf_)
      if (b.buffer && !b.mapped) vkCmdFillBuffer(cmd, b.buffer, 0, VK_WHOLE_SIZE, 0);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    stage(SIM_BIND_REST, topo.rest_pos.data(), 16ull * n, cmd);
    stage(SIM_BIND_UV, topo.uv.data(), 8ull * n, cmd);
    stage(SIM_BIND_ADJ_OFFSETS, topo.adj_offsets.data(), 4ull * topo.adj_offsets.size(), cmd);
    stage(SIM_BIND_ADJ_LIST, topo.adj_list.data(), 4ull * topo.adj_list.size(), cmd);
    stage(SIM_BIND_TRI_EDGES, topo.tri_edges.data(), 8ull * topo.tri_edges.size(), cmd);
    const std::vector<uint32_t> adj_mask = adjacencyMasks(topo);
    stage(SIM_BIND_ADJ_MASK, adj_mask.data(), 4ull * n, cmd);
    stage(SIM_BIND_CELL_START, last_start.data(), 4, cmd, 4ull * cells); // cell_start[T] = N, always
    std::vector<glm::vec4> normals(n, glm::vec4(0.0f, 0.0f, 1.0f, 0.0f));
    stage(SIM_BIND_NORMAL, normals.data(), 16ull * n, cmd);
    std::vector<glm::vec4> pos(n);
    for (uint32_t i = 0; i < n; ++i) pos[i] = startPosition(topo.rest_pos[i]);
    stage(SIM_BIND_POS, pos.data(), 16ull * n, cmd);
    stage(SIM_BIND_PREV, pos.data(), 16ull * n, cmd);
    stage(SIM_BIND_RESET_FROM, pos.data(), 16ull * n, cmd);
    uploadMutable(cmd, staging);
  });
  for (Buffer& b : staging) ctx_.destroyBuffer(b);

  // One descriptor set over every buffer.
  VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC, 1},
                                   {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kBindingCount - 1}};
  VkDescriptorPoolCreateInfo dpi{};
  dpi.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  dpi.maxSets = 1;
  dpi.poolSizeCount = 2;
  dpi.pPoolSizes = sizes;
  VK_CHECK(vkCreateDescriptorPool(dev, &dpi, nullptr, &descriptor_pool_));
  VkDescriptorSetAllocateInfo dai{};
  dai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  dai.descriptorPool = descriptor_pool_;
  dai.descriptorSetCount = 1;
  dai.pSetLayouts = &set_layout_;
  VK_CHECK(vkAllocateDescriptorSets(dev, &dai, &set_));
  std::vector<VkDescriptorBufferInfo> infos(kBindingCount);
  std::vector<VkWriteDescriptorSet> writes(kBindingCount);
  for (uint32_t b = 0; b < kBindingCount; ++b) {
    infos[b] = {buf_[b].buffer, 0, b == SIM_BIND_UNIFORMS ? VkDeviceSize(sizeof(SimUniforms)) : VK_WHOLE_SIZE};
    writes[b] = {};
    writes[b].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    writes[b].dstSet = set_;
    writes[b].dstBinding = b;
    writes[b].descriptorCount = 1;
    writes[b].descriptorType =
        b == SIM_BIND_UNIFORMS ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[b].pBufferInfo = &infos[b];
  }
  vkUpdateDescriptorSets(dev, kBindingCount, writes.data(), 0, nullptr);
  writeStaticUniforms();

  // Command buffers: per slot a tick (recorded on first use) and a reset; one normals buffer.
  VkCommandBufferAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  ai.commandPool = ctx_.commandPool();
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  for (uint32_t s = 0; s < kSlots; ++s) {
    VK_CHECK(vkAllocateCommandBuffers(dev, &ai, &slots_[s].tick));
    VK_CHECK(vkAllocateCommandBuffers(dev, &ai, &slots_[s].reset));
    recordReset(slots_[s], s);
  }
  VK_CHECK(vkAllocateCommandBuffers(dev, &ai, &normals_cmd_));
  recordNormals();
  uploaded_ = true;
}

void GpuSolver::uploadMutable(VkCommandBuffer cmd, std::vector<Buffer>& staging) {
  auto stage = [&](uint32_t binding, const void* data, VkDeviceSize bytes) {
    if (bytes == 0) return;
    Buffer s = ctx_.createHostBuffer(bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    std::memcpy(s.mapped, data, size_t(bytes));
    VkBufferCopy region{0, 0, bytes};
    vkCmdCopyBuffer(cmd, s.buffer, buf_[binding].buffer, 1, &region);
    staging.push_back(s);
  };
  // The arrays tearing changes: constraints, colour ranges, torn flags, triangles, counters.
  stage(SIM_BIND_CONSTRAINTS, topo_.constraints.data(), 16ull * topo_.constraintCount());
  std::vector<glm::uvec2> colors;
  for (const ColorRange& c : topo_.colors) colors.emplace_back(c.first, c.count);
  stage(SIM_BIND_COLOR_RANGES, colors.data(), 8ull * colors.size());
  std::vector<uint32_t> torn(topo_.constraintCount(), 0u);
  stage(SIM_BIND_TORN, torn.data(), 4ull * torn.size());
  stage(SIM_BIND_TRIANGLES, topo_.triangles.data(), 16ull * topo_.triangleCount());
  Counters counters = initialCounters(topo_.triangleCount());
  stage(SIM_BIND_COUNTERS, &counters, sizeof(counters));
}

void GpuSolver::writeStaticUniforms() {
  // What the normals and pick passes read outside a tick.
  SimUniforms u{};
  u.particle_count = topo_.particleCount();
  u.cols = topo_.cols;
  u.rows = topo_.rows;
  u.constraint_count = topo_.constraintCount();
  u.triangle_count = topo_.triangleCount();
  u.hash_mask = topo_.hash_size - 1;
  u.color_count = topo_.colorCount();
  u.grab_index = SIM_NONE;
  std::memcpy(static_cast<char*>(buf_[SIM_BIND_UNIFORMS].mapped) + kStaticSlot * uniform_stride_, &u, sizeof(u));
}

void GpuSolver::waitSlot(Slot& slot) const {
  if (!slot.pending) return;
  VK_CHECK(vkWaitForFences(ctx_.device(), 1, &slot.fence, VK_TRUE, UINT64_MAX));
  if (slot.timed) collectTimes(slot);
  slot.pending = slot.timed = false;
}

void GpuSolver::collectTimes(const Slot& slot) const {
  if (!slot.queries || slot.categories.empty()) return;
  std::vector<uint64_t> ts(slot.categories.size() + 1);
  VK_CHECK(vkGetQueryPoolResults(ctx_.device(), slot.queries, 0, uint32_t(ts.size()), ts.size() * sizeof(uint64_t),
                                 ts.data(), sizeof(uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
  std::array<double, kCategoryCount> ms{};
  for (size_t k = 0; k < slot.categories.size(); ++k)
    ms[slot.categories[k]] += double(ts[k + 1] - ts[k]) * ctx_.timestampPeriod() * 1e-6;
  ms[kNormals] = last_ms_[kNormals];
  last_ms_ = ms;
}

void GpuSolver::tick(const SimUniforms& u) {
  const uint32_t index = next_slot_;
  next_slot_ = (next_slot_ + 1) % kSlots;
  Slot& slot = slots_[index];
  // The slot's previous tick has finished: its uniforms and command buffer may be reused.
  waitSlot(slot);
  SimUniforms gpu_u = u;
  if (usesCollisionLists()) gpu_u.flags |= SIM_FLAG_NEAR;
  std::memcpy(static_cast<char*>(buf_[SIM_BIND_UNIFORMS].mapped) + index * uniform_stride_, &gpu_u, sizeof(gpu_u));
  if (u.reset_active) {
    ctx_.submit(slot.reset, slot.fence);
    slot.pending = true;
    dispatches_per_tick_ = 1;
    return;
  }
  RecordKey key{substepCount(u.substeps), u.iterations, (u.flags & SIM_FLAG_COLLISION) != 0u, usesFusedPath(u)};
  if (slot.recorded != key) recordTick(slot, index, key);
  ctx_.submit(slot.tick, slot.fence);
  slot.pending = true;
  slot.timed = true;
  last_tick_slot_ = int(index);
  dispatches_per_tick_ = slot.dispatches;
}

void GpuSolver::finish() {
  for (Slot& s : slots_) waitSlot(s);
  if (normals_pending_) {
    VK_CHECK(vkWaitForFences(ctx_.device(), 1, &normals_fence_, VK_TRUE, UINT64_MAX));
    normals_pending_ = false;
    if (normals_queries_) {
      uint64_t ts[2];
      VK_CHECK(vkGetQueryPoolResults(ctx_.device(), normals_queries_, 0, 2, sizeof(ts), ts, sizeof(uint64_t),
                                     VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
      last_ms_[kNormals] = double(ts[1] - ts[0]) * ctx_.timestampPeriod() * 1e-6;
    }
  }
}

void GpuSolver::beginReset() {
  finish();
  std::vector<Buffer> staging;
  ctx_.submitOnce([&](VkCommandBuffer cmd) {
    VkBufferCopy region{0, 0, 16ull * topo_.particleCount()};
    if (region.size) vkCmdCopyBuffer(cmd, buf_[SIM_BIND_POS].buffer, buf_[SIM_BIND_RESET_FROM].buffer, 1, &region);
    uploadMutable(cmd, staging);
  });
  for (Buffer& b : staging) ctx_.destroyBuffer(b);
}

void GpuSolver::computeNormals() {
  if (normals_pending_) finish();
  ctx_.submit(normals_cmd_, normals_fence_);
  normals_pending_ = true;
}

PickResult GpuSolver::pick(glm::vec3 o, glm::vec3 d, float radius) {
  finish();
  PickPush push{};
  push.origin_radius = vec4(o, radius);
  push.dir = vec4(d, 0.0f);
  push.count = topo_.particleCount();
  ctx_.submitOnce([&](VkCommandBuffer cmd) {
    PickResult init{};
    init.index = SIM_NONE;
    init.d2 = 0x7F800000u; // +inf
    vkCmdUpdateBuffer(cmd, buf_[SIM_BIND_PICK].buffer, 0, sizeof(init), &init);
    transferToCompute(cmd);
    bindSet(cmd, kStaticSlot);
    for (int s = 0; s < 3; ++s) {
      dispatchThreads(cmd, pipes_.pick[size_t(s)], push.count, push);
      computeToAll(cmd);
    }
    VkBufferCopy region{0, 0, sizeof(PickResult)};
    vkCmdCopyBuffer(cmd, buf_[SIM_BIND_PICK].buffer, small_readback_.buffer, 1, &region);
  });
  bound_ = VK_NULL_HANDLE;
  PickResult r;
  std::memcpy(&r, small_readback_.mapped, sizeof(r));
  return r;
}

glm::vec3 GpuSolver::particlePosition(uint32_t index) {
  finish();
  ctx_.submitOnce([&](VkCommandBuffer cmd) {
    VkBufferCopy region{16ull * index, 0, 16};
    vkCmdCopyBuffer(cmd, buf_[SIM_BIND_POS].buffer, small_readback_.buffer, 1, &region);
  });
  glm::vec4 p;
  std::memcpy(&p, small_readback_.mapped, sizeof(p));
  return glm::vec3(p);
}

void GpuSolver::readback(SimState& out) {
  finish();
  const uint32_t n = topo_.particleCount(), m = topo_.constraintCount(), t = topo_.triangleCount();
  out.pos.resize(n);
  out.prev.resize(n);
  out.normal.resize(n);
  out.constraints.resize(m);
  out.torn.resize(m);
  std::vector<glm::uvec2> colors(topo_.colorCount());
  std::vector<glm::uvec4> triangles(t);
  Counters counters{};
  struct Item {
    uint32_t binding;
    void* dst;
    VkDeviceSize bytes;
  };
  const Item items[] = {
      {SIM_BIND_POS, out.pos.data(), 16ull * n},         {SIM_BIND_PREV, out.prev.data(), 16ull * n},
      {SIM_BIND_NORMAL, out.normal.data(), 16ull * n},   {SIM_BIND_CONSTRAINTS, out.constraints.data(), 16ull * m},
      {SIM_BIND_TORN, out.torn.data(), 4ull * m},        {SIM_BIND_COLOR_RANGES, colors.data(), 8ull * colors.size()},
      {SIM_BIND_TRIANGLES, triangles.data(), 16ull * t}, {SIM_BIND_COUNTERS, &counters, sizeof(counters)}};
  VkDeviceSize total = 0;
  for (const Item& it : items) total += it.bytes;
  Buffer staging = ctx_.createHostBuffer(total, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  ctx_.submitOnce([&](VkCommandBuffer cmd) {
    VkDeviceSize off = 0;
    for (const Item& it : items) {
      VkBufferCopy region{0, off, it.bytes};
      if (it.bytes) vkCmdCopyBuffer(cmd, buf_[it.binding].buffer, staging.buffer, 1, &region);
      off += it.bytes;
    }
  });
  VkDeviceSize off = 0;
  for (const Item& it : items) {
    if (it.bytes) std::memcpy(it.dst, static_cast<const char*>(staging.mapped) + off, size_t(it.bytes));
    off += it.bytes;
  }
  ctx_.destroyBuffer(staging);
  out.colors.resize(colors.size());
  for (size_t c = 0; c < colors.size(); ++c) out.colors[c] = {colors[c].x, colors[c].y};
  out.triangle_count = counters.triangle_count;
  out.triangles.assign(triangles.begin(), triangles.begin() + std::min<uint32_t>(counters.triangle_count, t));
}

void GpuSolver::readHash(std::vector<uint32_t>& cell_start, std::vector<uint32_t>& cell_particles) {
  finish();
  cell_start.resize(topo_.hash_size + 1);
  cell_particles.resize(topo_.particleCount());
  ctx_.download(buf_[SIM_BIND_CELL_START], cell_start.data(), 4ull * cell_start.size());
  ctx_.download(buf_[SIM_BIND_CELL_PARTICLES], cell_particles.data(), 4ull * cell_particles.size());
}

PassTimes GpuSolver::passTimes() const {
  // Collect the newest finished tick without waiting for one still running.
  if (last_tick_slot_ >= 0) {
    Slot& s = slots_[size_t(last_tick_slot_)];
    if (s.pending && vkGetFenceStatus(ctx_.device(), s.fence) == VK_SUCCESS) waitSlot(s);
  }
  if (normals_pending_ && vkGetFenceStatus(ctx_.device(), normals_fence_) == VK_SUCCESS && normals_queries_) {
    uint64_t ts[2];
    VK_CHECK(vkGetQueryPoolResults(ctx_.device(), normals_queries_, 0, 2, sizeof(ts), ts, sizeof(uint64_t),
                                   VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
    last_ms_[kNormals] = double(ts[1] - ts[0]) * ctx_.timestampPeriod() * 1e-6;
    normals_pending_ = false;
  }
  static const char* kNames[kCategoryCount] = {"integrate", "project", "hash",    "collide",
                                               "floor",     "tear",    "normals", "fused_tick"};
  PassTimes t;
  for (int c = 0; c < kCategoryCount; ++c) t.ms.emplace_back(kNames[c], last_ms_[size_t(c)]);
  return t;
}

bool GpuSolver::usesFusedPath() const {
  return fused_allowed_ && pipes_.tick_fused.pipeline && topo_.particleCount() <= SIM_FUSED_MAX_PARTICLES &&
         topo_.hash_size <= SIM_FUSED_MAX_BUCKETS;
}

bool GpuSolver::usesFusedPath(const SimUniforms& u) const {
  if (!usesFusedPath()) return false;
  if ((u.flags & SIM_FLAG_COLLISION) == 0u || fused_max_cell_spacings_ < 0.0f) return true;
  return u.inv_cell * fused_max_cell_spacings_ * spacing_ >= 1.0f;
}

uint64_t GpuSolver::memoryBytes() const {
  uint64_t bytes = 0;
  for (const Buffer& b : buf_) bytes += b.size;
  return bytes;
}

} // namespace tender::gpu
