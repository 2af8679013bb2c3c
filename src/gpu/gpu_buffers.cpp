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
#include "gpu/sheet_buffers.h"

namespace tender::gpu {

using namespace shaderio;

namespace {

/// Usage of every simulation buffer: storage, copies, and the renderer's vertex/index/indirect reads.
constexpr VkBufferUsageFlags kStorageUsage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                             VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_VERTEX_BUFFER_BIT |
                                             VK_BUFFER_USAGE_INDEX_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT;

} // namespace

void GpuSolver::destroySheet() {
  VkDevice dev = ctx_.device();
  for (InFlight& s : in_flight_) {
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
  last_tick_ = -1;
  uploaded_ = false;
}

void GpuSolver::upload(const SheetTopology& topo) {
  VkDevice dev = ctx_.device();
  VK_CHECK(vkDeviceWaitIdle(dev));
  destroySheet();
  topo_ = topo;
  spacing_ = structuralSpacing(topo);
  const VkDeviceSize max_range = ctx_.properties().limits.maxStorageBufferRange;
  layout_sizes_ = SheetLayout::of(topo, max_range, topo.contact);
  hash_grids_.clear();
  hash_grids_uploaded_.clear();
  contact_grids_uploaded_.clear();

  // The uniforms (host-visible, a copy per tick in flight and one static), then the table.
  const VkDeviceSize align = ctx_.properties().limits.minUniformBufferOffsetAlignment;
  uniform_stride_ = (sizeof(SimUniforms) + align - 1) / align * align;
  buf_[SIM_BIND_UNIFORMS] =
      ctx_.createHostBuffer(uniform_stride_ * (kInFlight + 1), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  StartData start;
  const std::vector<BindingSpec> table = sheetBindings(topo_, layout_sizes_, start, true);
  // A sheet whose arrays exceed what the device binds is refused with one line, before allocating.
  for (const BindingSpec& b : table)
    if (b.bytes > max_range)
      throw std::runtime_error("a " + std::to_string(topo.cols) + "x" + std::to_string(topo.rows) + " sheet needs a " +
                               std::to_string(b.bytes >> 20) + " MiB buffer (binding " + std::to_string(b.binding) +
                               "); this Vulkan device binds at most " + std::to_string(max_range >> 20) +
                               " MiB (try a smaller sheet or --backend cpu)");
  for (const BindingSpec& b : table) buf_[b.binding] = ctx_.createDeviceBuffer(b.bytes, kStorageUsage);
  uploadStart(ctx_, place(), table);

  // One descriptor set over every buffer.
  descriptor_pool_ = createSheetSetPool(dev, 1);
  set_ = allocateDescriptorSets(dev, descriptor_pool_, set_layout_, 1)[0];
  std::array<VkDescriptorBufferInfo, kSheetBindingCount> where{};
  for (uint32_t b = 0; b < kBindingCount; ++b)
    where[b] = {buf_[b].buffer, 0, b == SIM_BIND_UNIFORMS ? VkDeviceSize(sizeof(SimUniforms)) : VK_WHOLE_SIZE};
  writeSheetSet(dev, set_, where);
  writeStaticUniforms();

  // Command buffers: per tick in flight a tick (recorded on first use) and a reset; one normals buffer.
  VkCommandBufferAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  ai.commandPool = ctx_.commandPool();
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  for (uint32_t s = 0; s < kInFlight; ++s) {
    VK_CHECK(vkAllocateCommandBuffers(dev, &ai, &in_flight_[s].tick));
    VK_CHECK(vkAllocateCommandBuffers(dev, &ai, &in_flight_[s].reset));
    recordReset(in_flight_[s], s);
  }
  VK_CHECK(vkAllocateCommandBuffers(dev, &ai, &normals_cmd_));
  recordNormals();
  uploaded_ = true;
}

void GpuSolver::sizeContact() {
  VkDevice dev = ctx_.device();
  finish();
  VK_CHECK(vkDeviceWaitIdle(dev));
  const VkDeviceSize max_range = ctx_.properties().limits.maxStorageBufferRange;
  const SheetLayout sizes = SheetLayout::of(topo_, max_range, true);
  StartData start;
  std::vector<BindingSpec> table = sheetBindings(topo_, sizes, start, false);
  std::erase_if(table, [](const BindingSpec& b) {
    return b.binding != SIM_BIND_SCRATCH && b.binding != SIM_BIND_CONTACT_LISTS && b.binding != SIM_BIND_CONTACT &&
           b.binding != SIM_BIND_CONTACT_GRID;
  });
  for (const BindingSpec& b : table)
    if (b.bytes > max_range)
      throw std::runtime_error("contact on a " + std::to_string(topo_.cols) + "x" + std::to_string(topo_.rows) +
                               " sheet needs a " + std::to_string(b.bytes >> 20) + " MiB buffer (binding " +
                               std::to_string(b.binding) + "); this Vulkan device binds at most " +
                               std::to_string(max_range >> 20) + " MiB (try a smaller sheet or --backend cpu)");
  // New buffers for these bindings (their old ones are idle), their start contents, and the
  // descriptor set pointed at them: the command buffers recorded over it are recorded again
  std::vector<Buffer> made;
  try {
    for (const BindingSpec& b : table) made.push_back(ctx_.createDeviceBuffer(b.bytes, kStorageUsage));
  } catch (const VulkanError&) {
    for (Buffer& b : made) ctx_.destroyBuffer(b);
    throw std::runtime_error("contact on a " + std::to_string(topo_.cols) + "x" + std::to_string(topo_.rows) +
                             " sheet does not fit the memory of Vulkan device " + ctx_.info().name +
                             " (try a smaller sheet or --backend cpu)");
  }
  for (size_t k = 0; k < table.size(); ++k) {
    ctx_.destroyBuffer(buf_[table[k].binding]);
    buf_[table[k].binding] = made[k];
  }
  uploadStart(ctx_, place(), table);
  layout_sizes_ = sizes;
  std::array<VkDescriptorBufferInfo, kSheetBindingCount> where{};
  for (uint32_t b = 0; b < kBindingCount; ++b)
    where[b] = {buf_[b].buffer, 0, b == SIM_BIND_UNIFORMS ? VkDeviceSize(sizeof(SimUniforms)) : VK_WHOLE_SIZE};
  writeSheetSet(dev, set_, where);
  for (uint32_t s = 0; s < kInFlight; ++s) {
    in_flight_[s].recorded.reset();
    recordReset(in_flight_[s], s);
  }
  recordNormals();
}

int64_t GpuSolver::contacts() const {
  if (!last_contact_ || !layout_sizes_.contact) return -1;
  const_cast<GpuSolver*>(this)->finish();
  return readContactCount(ctx_, buf_[SIM_BIND_CONTACT_GRID], 0);
}

uint32_t GpuSolver::contactListBuilds() {
  if (!layout_sizes_.contact) return 0;
  finish();
  uint32_t header[SIM_CONTACT_LIST_HEADER];
  ctx_.download(buf_[SIM_BIND_CONTACT_LISTS], header, sizeof(header), 16ull * layout_sizes_.contact_edges);
  return header[2];
}

SheetPlace GpuSolver::place() const {
  SheetPlace where;
  for (uint32_t b = 0; b < kBindingCount; ++b) {
    where.buffer[b] = buf_[b].buffer;
    where.size[b] = VK_WHOLE_SIZE;
  }
  return where;
}

void GpuSolver::beginReset() {
  finish();
  beginSheetReset(ctx_, place(), topo_, layout_sizes_);
}

void GpuSolver::readback(SimState& out) {
  finish();
  readSheetState(ctx_, place(), topo_, layout_sizes_, out);
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
