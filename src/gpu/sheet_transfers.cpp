// A sheet's uploads, resets and read-backs, wherever its bindings live (SheetPlace): the one
// implementation GpuSolver and GpuBatch share.
#include <algorithm>
#include <cstring>

#include "gpu/barriers.h"
#include "gpu/context.h"
#include "gpu/sheet_buffers.h"

namespace tender::gpu {

using namespace shaderio;

void recordStart(VulkanContext& ctx, VkCommandBuffer cmd, const SheetPlace& place,
                 const std::vector<BindingSpec>& table, bool restored_only, Buffer& staging) {
  auto takes = [&](const BindingSpec& b) { return !restored_only || b.restored; };
  VkDeviceSize total = 0;
  for (const BindingSpec& b : table)
    if (takes(b) && b.data && b.data_bytes) total += alignUp(b.data_bytes, 16);
  staging = ctx.createHostBuffer(std::max<VkDeviceSize>(total, 16), VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  // Zeros first, then the start contents over them
  for (const BindingSpec& b : table)
    if (takes(b)) vkCmdFillBuffer(cmd, place.buffer[b.binding], place.offset[b.binding], place.size[b.binding], 0);
  memoryBarrier(cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                VK_ACCESS_2_TRANSFER_WRITE_BIT);
  VkDeviceSize at = 0;
  for (const BindingSpec& b : table) {
    if (!takes(b) || !b.data || b.data_bytes == 0) continue;
    std::memcpy(static_cast<char*>(staging.mapped) + at, b.data, size_t(b.data_bytes));
    VkBufferCopy region{at, place.offset[b.binding] + b.data_offset, b.data_bytes};
    vkCmdCopyBuffer(cmd, staging.buffer, place.buffer[b.binding], 1, &region);
    at += alignUp(b.data_bytes, 16);
  }
}

void uploadStart(VulkanContext& ctx, const SheetPlace& place, const std::vector<BindingSpec>& table) {
  Buffer staging;
  ctx.submitOnce([&](VkCommandBuffer cmd) { recordStart(ctx, cmd, place, table, false, staging); });
  ctx.destroyBuffer(staging);
}

void beginSheetReset(VulkanContext& ctx, const SheetPlace& place, const SheetTopology& topo, const SheetLayout& sizes) {
  StartData start;
  const std::vector<BindingSpec> table = sheetBindings(topo, sizes, start, false);
  Buffer staging;
  ctx.submitOnce([&](VkCommandBuffer cmd) {
    // The reset animates from where the sheet is now; what tearing changed is restored.
    VkBufferCopy region{place.offset[SIM_BIND_POS], place.offset[SIM_BIND_RESET_FROM], 16ull * topo.particleCount()};
    if (region.size) vkCmdCopyBuffer(cmd, place.buffer[SIM_BIND_POS], place.buffer[SIM_BIND_RESET_FROM], 1, &region);
    recordStart(ctx, cmd, place, table, true, staging);
  });
  ctx.destroyBuffer(staging);
}

void readSheetState(VulkanContext& ctx, const SheetPlace& place, const SheetTopology& topo, const SheetLayout& sizes,
                    SimState& out) {
  StartData start;
  const std::vector<BindingSpec> table = sheetBindings(topo, sizes, start, false);
  std::array<VkDeviceSize, kSheetBindingCount> offset{};
  VkDeviceSize total = 0;
  for (const BindingSpec& b : table)
    if (b.read_back) {
      offset[b.binding] = total;
      total += alignUp(b.bytes, 16);
    }
  Buffer staging = ctx.createHostBuffer(std::max<VkDeviceSize>(total, 16), VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  ctx.submitOnce([&](VkCommandBuffer cmd) {
    for (const BindingSpec& b : table)
      if (b.read_back && b.bytes > 0) {
        VkBufferCopy region{place.offset[b.binding], offset[b.binding], b.bytes};
        vkCmdCopyBuffer(cmd, place.buffer[b.binding], staging.buffer, 1, &region);
      }
  });
  assembleState(
      topo, [&](uint32_t binding) { return static_cast<const char*>(staging.mapped) + offset[binding]; }, out);
  ctx.destroyBuffer(staging);
}

int64_t readContactCount(VulkanContext& ctx, const Buffer& grid, VkDeviceSize offset) {
  uint32_t header[SIM_CONTACT_HEADER];
  ctx.download(grid, header, sizeof(header), offset);
  return header[2]; // CONTACT_COUNT (contact_grid.glsl)
}

} // namespace tender::gpu
