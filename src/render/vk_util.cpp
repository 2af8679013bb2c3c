#include "vk_util.h"

namespace tender::render {

Image createImage(gpu::VulkanContext& ctx, const ImageDesc& d) {
  VkDevice dev = ctx.device();
  Image img;
  img.format = d.format;
  img.extent = d.extent;
  img.mip_levels = d.mip_levels;
  VkImageCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
  ci.imageType = VK_IMAGE_TYPE_2D;
  ci.format = d.format;
  ci.extent = {d.extent.width, d.extent.height, 1};
  ci.mipLevels = d.mip_levels;
  ci.arrayLayers = 1;
  ci.samples = d.samples;
  ci.tiling = VK_IMAGE_TILING_OPTIMAL;
  ci.usage = d.usage;
  ci.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VK_CHECK(vkCreateImage(dev, &ci, nullptr, &img.image));
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(dev, img.image, &req);
  VkMemoryAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  ai.allocationSize = req.size;
  ai.memoryTypeIndex = ctx.findMemoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  if (ai.memoryTypeIndex == UINT32_MAX) ai.memoryTypeIndex = ctx.findMemoryType(req.memoryTypeBits, 0);
  VK_CHECK(vkAllocateMemory(dev, &ai, nullptr, &img.memory));
  VK_CHECK(vkBindImageMemory(dev, img.image, img.memory, 0));
  VkImageViewCreateInfo vi{};
  vi.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
  vi.image = img.image;
  vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vi.format = d.format;
  vi.subresourceRange = {d.aspect, 0, d.mip_levels, 0, 1};
  VK_CHECK(vkCreateImageView(dev, &vi, nullptr, &img.view));
  return img;
}

void destroyImage(VkDevice device, Image& image) {
  if (image.view) vkDestroyImageView(device, image.view, nullptr);
  if (image.image) vkDestroyImage(device, image.image, nullptr);
  if (image.memory) vkFreeMemory(device, image.memory, nullptr);
  image = Image{};
}

VkShaderModule createShaderModule(VkDevice device, std::span<const uint32_t> spirv) {
  VkShaderModuleCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  ci.codeSize = spirv.size_bytes();
  ci.pCode = spirv.data();
  VkShaderModule m = VK_NULL_HANDLE;
  VK_CHECK(vkCreateShaderModule(device, &ci, nullptr, &m));
  return m;
}

void transitionImage(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect, VkImageLayout from,
                     VkImageLayout to, uint32_t first_mip, uint32_t mips) {
  VkImageMemoryBarrier2 b{};
  b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2;
  b.srcStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
  b.srcAccessMask = VK_ACCESS_2_MEMORY_WRITE_BIT;
  b.dstStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
  b.dstAccessMask = VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT;
  b.oldLayout = from;
  b.newLayout = to;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = image;
  b.subresourceRange = {aspect, first_mip, mips, 0, 1};
  VkDependencyInfo di{};
  di.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO;
  di.imageMemoryBarrierCount = 1;
  di.pImageMemoryBarriers = &b;
  vkCmdPipelineBarrier2(cmd, &di);
}

} // namespace tender::render
