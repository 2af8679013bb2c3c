// The sheet's storage buffers, driven by one table of bindings: the size of each from the topology,
// its start contents, whether a reset restores it and whether readback() copies it. The table
// drives allocation, the descriptor set, staging, readback and memoryBytes().
#include <algorithm>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "gpu/barriers.h"
#include "gpu/gpu_solver.h"

namespace tender::gpu {

using namespace shaderio;

namespace {

/// Usage of every simulation buffer: storage, copies, and the renderer's vertex/index/indirect reads.
constexpr VkBufferUsageFlags kStorageUsage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                             VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_VERTEX_BUFFER_BIT |
                                             VK_BUFFER_USAGE_INDEX_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT;

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

template <class T>
VkDeviceSize bytesOf(const std::vector<T>& v) {
  return VkDeviceSize(v.size()) * sizeof(T);
}

} // namespace

uint32_t GpuSolver::scanSumsSize(uint32_t count) {
  uint32_t groups = (count + SIM_SCAN_BLOCK - 1) / SIM_SCAN_BLOCK;
  return groups + (groups > 1 ? scanSumsSize(groups) : 0);
}

std::vector<GpuSolver::BindingSpec> GpuSolver::bindingTable(StartData& d, bool particle_data) const {
  const SheetTopology& topo = topo_;
  const uint32_t n = topo.particleCount(), m = topo.constraintCount(), t = topo.triangleCount();
  const uint32_t cells = topo.hash_size;
  // The fused tick's scans meet their per-invocation totals in the SIM_WG_FUSED slots after the
  // compaction slots (the separate passes' block sums, unused on that path).
  const uint32_t scratch = std::max(hash_sums_ + scanSumsSize(cells), tear_slots_ + SIM_WG_FUSED);
  const VkDeviceSize list_bytes = candidates_fit_ ? 4ull * SIM_CANDIDATE_STRIDE * n : 16,
                     list_base = candidates_fit_ ? 16ull * n : 16;

  // Start contents derived from the topology; the per-particle ones only for an upload.
  if (particle_data) {
    d.pos.resize(n);
    for (uint32_t i = 0; i < n; ++i) d.pos[i] = startPosition(topo.rest_pos[i]);
    d.normal.assign(n, glm::vec4(0.0f, 0.0f, 1.0f, 0.0f));
    d.adj_mask = adjacencyMasks(topo);
  }
  d.last_start = n; // cell_start[T] = N, always
  d.colors.clear();
  for (const ColorRange& c : topo.colors) d.colors.emplace_back(c.first, c.count);
  d.counters = Counters{};
  d.counters.triangle_count = t;
  d.counters.compact_dispatch = uvec4(0u, 1u, 1u, 0u);
  d.counters.draw_args = uvec4(3u * t, 1u, 0u, 0u);

  enum : uint8_t { kPlain = 0, kRestored = 1, kReadBack = 2 };
  auto spec = [](uint32_t binding, VkDeviceSize bytes, const void* data = nullptr, VkDeviceSize data_bytes = 0,
                 uint8_t flags = kPlain, VkDeviceSize offset = 0) {
    return BindingSpec{binding, bytes, data, data_bytes, offset, (flags & kRestored) != 0, (flags & kReadBack) != 0};
  };
  return {
      // Particles
      spec(SIM_BIND_POS, 16ull * n, d.pos.data(), bytesOf(d.pos), kReadBack),
      spec(SIM_BIND_PREV, 16ull * n, d.pos.data(), bytesOf(d.pos), kReadBack),
      spec(SIM_BIND_REST, 16ull * n, topo.rest_pos.data(), bytesOf(topo.rest_pos)),
      spec(SIM_BIND_UV, 8ull * n, topo.uv.data(), bytesOf(topo.uv)),
      spec(SIM_BIND_NORMAL, 16ull * n, d.normal.data(), bytesOf(d.normal), kReadBack),
      spec(SIM_BIND_RESET_FROM, 16ull * n, d.pos.data(), bytesOf(d.pos)),
      spec(SIM_BIND_DELTA, 16ull * n),
      // Constraints and what tearing changes (a reset restores them)
      spec(SIM_BIND_CONSTRAINTS, 16ull * m, topo.constraints.data(), bytesOf(topo.constraints), kRestored | kReadBack),
      spec(SIM_BIND_COLOR_RANGES, 8ull * topo.colorCount(), d.colors.data(), bytesOf(d.colors), kRestored | kReadBack),
      spec(SIM_BIND_TORN, 4ull * m, nullptr, 0, kRestored | kReadBack),
      spec(SIM_BIND_TRIANGLES, 16ull * t, topo.triangles.data(), bytesOf(topo.triangles), kRestored | kReadBack),
      spec(SIM_BIND_COUNTERS, sizeof(Counters), &d.counters, sizeof(Counters), kRestored | kReadBack),
      spec(SIM_BIND_TRI_EDGES, 8ull * t, topo.tri_edges.data(), bytesOf(topo.tri_edges)),
      spec(SIM_BIND_COMPACT_TMP, 16ull * (m + t)),
      spec(SIM_BIND_SCRATCH, 4ull * scratch),
      // Collision: adjacency, the spatial hash, the candidate lists
      spec(SIM_BIND_ADJ_OFFSETS, 4ull * topo.adj_offsets.size(), topo.adj_offsets.data(), bytesOf(topo.adj_offsets)),
      spec(SIM_BIND_ADJ_LIST, 4ull * topo.adj_list.size(), topo.adj_list.data(), bytesOf(topo.adj_list)),
      spec(SIM_BIND_ADJ_MASK, 4ull * n, d.adj_mask.data(), bytesOf(d.adj_mask)),
      spec(SIM_BIND_CELL_COUNT, 4ull * cells),
      spec(SIM_BIND_CELL_START, 4ull * (cells + 1), &d.last_start, 4, kPlain, 4ull * cells),
      spec(SIM_BIND_CELL_PARTICLES, 4ull * n),
      spec(SIM_BIND_PARTICLE_CELL, 4ull * n),
      spec(SIM_BIND_CELL_SCATTER, 4ull * n),
      spec(SIM_BIND_CELL_POS, 16ull * n),
      spec(SIM_BIND_CANDIDATES, list_bytes),
      spec(SIM_BIND_CANDIDATE_BASE, list_base),
      spec(SIM_BIND_HASH_ARGS, 16ull * 2 * SIM_HASH_DISPATCHES),
      // Interaction
      spec(SIM_BIND_PICK, sizeof(PickResult)),
  };
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
  tear_slots_ = topo.constraintCount() + topo.triangleCount() + 1;
  tear_sums_ = tear_slots_;
  hash_sums_ = tear_sums_ + scanSumsSize(tear_slots_);
  const VkDeviceSize max_range = ctx_.properties().limits.maxStorageBufferRange;
  // Collision candidate lists, when the largest binding holds them
  candidates_fit_ = 4ull * SIM_CANDIDATE_STRIDE * topo.particleCount() <= max_range;
  hash_grids_.clear();
  hash_grids_uploaded_.clear();

  // The uniforms (host-visible, one slot per tick in flight and one static), then the table.
  const VkDeviceSize align = ctx_.properties().limits.minUniformBufferOffsetAlignment;
  uniform_stride_ = (sizeof(SimUniforms) + align - 1) / align * align;
  buf_[SIM_BIND_UNIFORMS] = ctx_.createHostBuffer(uniform_stride_ * (kSlots + 1), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  StartData start;
  const std::vector<BindingSpec> table = bindingTable(start, true);
  // A sheet whose arrays exceed what the device binds is refused with one line, before allocating.
  for (const BindingSpec& b : table)
    if (b.bytes > max_range)
      throw std::runtime_error("a " + std::to_string(topo.cols) + "x" + std::to_string(topo.rows) + " sheet needs a " +
                               std::to_string(b.bytes >> 20) + " MiB buffer (binding " + std::to_string(b.binding) +
                               "); this Vulkan device binds at most " + std::to_string(max_range >> 20) +
                               " MiB (try a smaller sheet or --backend cpu)");
  for (const BindingSpec& b : table) buf_[b.binding] = ctx_.createDeviceBuffer(b.bytes, kStorageUsage);
  std::vector<Buffer> staging;
  ctx_.submitOnce([&](VkCommandBuffer cmd) { stageBindings(cmd, table, false, staging); });
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

void GpuSolver::stageBindings(VkCommandBuffer cmd, const std::vector<BindingSpec>& table, bool restored_only,
                              std::vector<Buffer>& staging) {
  // Zeros first, then the start contents over them.
  for (const BindingSpec& b : table)
    if (!restored_only || b.restored) vkCmdFillBuffer(cmd, buf_[b.binding].buffer, 0, VK_WHOLE_SIZE, 0);
  memoryBarrier(cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                VK_ACCESS_2_TRANSFER_WRITE_BIT);
  for (const BindingSpec& b : table) {
    if ((restored_only && !b.restored) || !b.data || b.data_bytes == 0) continue;
    Buffer s = ctx_.createHostBuffer(b.data_bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    std::memcpy(s.mapped, b.data, size_t(b.data_bytes));
    VkBufferCopy region{0, b.data_offset, b.data_bytes};
    vkCmdCopyBuffer(cmd, s.buffer, buf_[b.binding].buffer, 1, &region);
    staging.push_back(s);
  }
}

void GpuSolver::beginReset() {
  finish();
  StartData start;
  const std::vector<BindingSpec> table = bindingTable(start, false);
  std::vector<Buffer> staging;
  ctx_.submitOnce([&](VkCommandBuffer cmd) {
    // The reset animates from where the sheet is now; what tearing changed is restored.
    VkBufferCopy region{0, 0, 16ull * topo_.particleCount()};
    if (region.size) vkCmdCopyBuffer(cmd, buf_[SIM_BIND_POS].buffer, buf_[SIM_BIND_RESET_FROM].buffer, 1, &region);
    stageBindings(cmd, table, true, staging);
  });
  for (Buffer& b : staging) ctx_.destroyBuffer(b);
}

void GpuSolver::readback(SimState& out) {
  finish();
  StartData start;
  const std::vector<BindingSpec> table = bindingTable(start, false);
  // Every read-back binding into one staging buffer, one after the other.
  std::array<VkDeviceSize, kBindingCount> offset{};
  VkDeviceSize total = 0;
  for (const BindingSpec& b : table)
    if (b.read_back) {
      offset[b.binding] = total;
      total += b.bytes;
    }
  Buffer staging = ctx_.createHostBuffer(total, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  ctx_.submitOnce([&](VkCommandBuffer cmd) {
    for (const BindingSpec& b : table)
      if (b.read_back && b.bytes > 0) {
        VkBufferCopy region{0, offset[b.binding], b.bytes};
        vkCmdCopyBuffer(cmd, buf_[b.binding].buffer, staging.buffer, 1, &region);
      }
  });
  auto take = [&]<class T>(uint32_t binding, std::vector<T>& v, size_t count) {
    v.resize(count);
    if (count) std::memcpy(v.data(), static_cast<const char*>(staging.mapped) + offset[binding], count * sizeof(T));
  };
  const uint32_t n = topo_.particleCount(), m = topo_.constraintCount();
  take(SIM_BIND_POS, out.pos, n);
  take(SIM_BIND_PREV, out.prev, n);
  take(SIM_BIND_NORMAL, out.normal, n);
  take(SIM_BIND_CONSTRAINTS, out.constraints, m);
  take(SIM_BIND_TORN, out.torn, m);
  std::vector<glm::uvec2> colors;
  take(SIM_BIND_COLOR_RANGES, colors, topo_.colorCount());
  std::vector<glm::uvec4> triangles;
  take(SIM_BIND_TRIANGLES, triangles, topo_.triangleCount());
  Counters counters{};
  std::memcpy(&counters, static_cast<const char*>(staging.mapped) + offset[SIM_BIND_COUNTERS], sizeof(counters));
  ctx_.destroyBuffer(staging);
  out.colors.resize(colors.size());
  for (size_t c = 0; c < colors.size(); ++c) out.colors[c] = {colors[c].x, colors[c].y};
  out.triangle_count = std::min<uint32_t>(counters.triangle_count, topo_.triangleCount());
  out.triangles.assign(triangles.begin(), triangles.begin() + out.triangle_count);
}

void GpuSolver::readDeltas(std::vector<glm::vec4>& out) {
  finish();
  out.resize(topo_.particleCount());
  ctx_.download(buf_[SIM_BIND_DELTA], out.data(), 16ull * out.size());
}

void GpuSolver::readHash(std::vector<uint32_t>& cell_start, std::vector<uint32_t>& cell_particles) {
  finish();
  cell_start.resize(topo_.hash_size + 1);
  cell_particles.resize(topo_.particleCount());
  ctx_.download(buf_[SIM_BIND_CELL_START], cell_start.data(), 4ull * cell_start.size());
  ctx_.download(buf_[SIM_BIND_CELL_PARTICLES], cell_particles.data(), 4ull * cell_particles.size());
}

uint64_t GpuSolver::memoryBytes() const {
  uint64_t total = 0;
  for (const Buffer& b : buf_) total += b.size;
  return total;
}

} // namespace tender::gpu
