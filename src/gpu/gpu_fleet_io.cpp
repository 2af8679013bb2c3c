// GpuFleet's transfers: a sheet's uploads, resets and read-backs of its slices, and every sheet's
// positions in one read-back (gpu_fleet.h); gpu_fleet.cpp creates the fleet and runs its ticks.
#include <cstring>

#include "core/host_queries.h"
#include "gpu/barriers.h"
#include "gpu_fleet.h"

namespace tender::gpu {

using namespace shaderio;

void GpuFleet::stage(VkCommandBuffer cmd, uint32_t i, const std::vector<BindingSpec>& table, bool restored_only,
                     Buffer& staging) {
  // Zeros first, then the start contents over them, from one staging buffer.
  VkDeviceSize total = 0;
  for (const BindingSpec& b : table)
    if ((!restored_only || b.restored) && b.data && b.data_bytes) total += alignUp(b.data_bytes, 16);
  staging = ctx_.createHostBuffer(std::max<VkDeviceSize>(total, 16), VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  for (const BindingSpec& b : table)
    if (!restored_only || b.restored)
      vkCmdFillBuffer(cmd, buf_[b.binding].buffer, sliceOffset(b.binding, i), stride_[b.binding], 0);
  memoryBarrier(cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                VK_ACCESS_2_TRANSFER_WRITE_BIT);
  VkDeviceSize at = 0;
  for (const BindingSpec& b : table) {
    if ((restored_only && !b.restored) || !b.data || b.data_bytes == 0) continue;
    std::memcpy(static_cast<char*>(staging.mapped) + at, b.data, size_t(b.data_bytes));
    VkBufferCopy region{at, sliceOffset(b.binding, i) + b.data_offset, b.data_bytes};
    vkCmdCopyBuffer(cmd, staging.buffer, buf_[b.binding].buffer, 1, &region);
    at += alignUp(b.data_bytes, 16);
  }
}

void GpuFleet::uploadSheet(uint32_t i, const SheetTopology& topo) {
  finish();
  if (!allocated_) allocate(topo);
  // Every sheet shares the topology: the restored bindings of a reset come from topo_.
  if (topo.cols != topo_.cols || topo.rows != topo_.rows || topo.constraints.size() != topo_.constraints.size() ||
      topo.triangles.size() != topo_.triangles.size() || topo.colors.size() != topo_.colors.size() ||
      std::memcmp(topo.constraints.data(), topo_.constraints.data(), topo.constraints.size() * sizeof(Constraint)) != 0)
    throw std::invalid_argument("the sheets of a fleet share their topology (grid, spacing and constraint families)");
  StartData start;
  const std::vector<BindingSpec> table = sheetBindings(topo, sizes_, start, true);
  Buffer staging;
  ctx_.submitOnce([&](VkCommandBuffer cmd) { stage(cmd, i, table, false, staging); });
  ctx_.destroyBuffer(staging);
}

void GpuFleet::resetSheet(uint32_t i) {
  finish();
  StartData start;
  const std::vector<BindingSpec> table = sheetBindings(topo_, sizes_, start, false);
  Buffer staging;
  ctx_.submitOnce([&](VkCommandBuffer cmd) {
    // The reset animates from where the sheet is now; what tearing changed is restored.
    VkBufferCopy region{sliceOffset(SIM_BIND_POS, i), sliceOffset(SIM_BIND_RESET_FROM, i),
                        16ull * topo_.particleCount()};
    if (region.size) vkCmdCopyBuffer(cmd, buf_[SIM_BIND_POS].buffer, buf_[SIM_BIND_RESET_FROM].buffer, 1, &region);
    stage(cmd, i, table, true, staging);
  });
  ctx_.destroyBuffer(staging);
}

Buffer GpuFleet::download(const std::vector<std::pair<uint32_t, VkDeviceSize>>& slices, uint32_t sheet,
                          std::vector<VkDeviceSize>& offsets) {
  finish();
  offsets.assign(SIM_BATCH_ENTRIES, 0);
  VkDeviceSize total = 0;
  for (auto [binding, bytes] : slices) {
    offsets[binding] = total;
    total += alignUp(bytes, 16);
  }
  Buffer staging = ctx_.createHostBuffer(std::max<VkDeviceSize>(total, 16), VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  ctx_.submitOnce([&](VkCommandBuffer cmd) {
    for (auto [binding, bytes] : slices)
      if (bytes) {
        VkBufferCopy region{sliceOffset(binding, sheet), offsets[binding], bytes};
        vkCmdCopyBuffer(cmd, buf_[binding].buffer, staging.buffer, 1, &region);
      }
  });
  return staging;
}

void GpuFleet::readSheet(uint32_t i, SimState& out) {
  StartData start;
  std::vector<std::pair<uint32_t, VkDeviceSize>> slices;
  for (const BindingSpec& b : sheetBindings(topo_, sizes_, start, false))
    if (b.read_back) slices.emplace_back(b.binding, b.bytes);
  std::vector<VkDeviceSize> offsets;
  Buffer staging = download(slices, i, offsets);
  assembleState(
      topo_, [&](uint32_t binding) { return static_cast<const char*>(staging.mapped) + offsets[binding]; }, out);
  ctx_.destroyBuffer(staging);
  gridNormals(out.pos, topo_.cols, topo_.rows, out.normal);
}

glm::vec4 GpuFleet::readParticle(uint32_t i, uint32_t particle) {
  finish();
  glm::vec4 p;
  ctx_.download(buf_[SIM_BIND_POS], &p, sizeof(p), sliceOffset(SIM_BIND_POS, i) + 16ull * particle);
  return p;
}

std::vector<glm::vec4> GpuFleet::readSheetPositions(uint32_t i) {
  finish();
  std::vector<glm::vec4> pos(topo_.particleCount());
  ctx_.download(buf_[SIM_BIND_POS], pos.data(), 16ull * pos.size(), sliceOffset(SIM_BIND_POS, i));
  return pos;
}

void GpuFleet::readSheetDeltas(uint32_t i, std::vector<glm::vec4>& out) {
  finish();
  out.resize(topo_.particleCount());
  ctx_.download(buf_[SIM_BIND_DELTA], out.data(), 16ull * out.size(), sliceOffset(SIM_BIND_DELTA, i));
}

void GpuFleet::readPositions(std::vector<glm::vec4>& pos, std::vector<glm::vec4>& prev) {
  flush();
  finish();
  const uint32_t n = topo_.particleCount();
  const VkDeviceSize bytes = 16ull * n * size();
  pos.resize(size_t(n) * size());
  prev.resize(pos.size());
  if (!allocated_ || bytes == 0) return;
  // Both arrays of every sheet into one host buffer, in one submission.
  Buffer staging = ctx_.createHostBuffer(2 * bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  ctx_.submitOnce([&](VkCommandBuffer cmd) {
    std::vector<VkBufferCopy> pos_regions, prev_regions;
    for (uint32_t i = 0; i < size(); ++i) {
      pos_regions.push_back({sliceOffset(SIM_BIND_POS, i), 16ull * n * i, 16ull * n});
      prev_regions.push_back({sliceOffset(SIM_BIND_PREV, i), bytes + 16ull * n * i, 16ull * n});
    }
    vkCmdCopyBuffer(cmd, buf_[SIM_BIND_POS].buffer, staging.buffer, uint32_t(pos_regions.size()), pos_regions.data());
    vkCmdCopyBuffer(cmd, buf_[SIM_BIND_PREV].buffer, staging.buffer, uint32_t(prev_regions.size()),
                    prev_regions.data());
  });
  std::memcpy(pos.data(), staging.mapped, size_t(bytes));
  std::memcpy(prev.data(), static_cast<const char*>(staging.mapped) + bytes, size_t(bytes));
  ctx_.destroyBuffer(staging);
}

} // namespace tender::gpu
