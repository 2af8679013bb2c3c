#pragma once
/// Small Vulkan helpers of the renderer: images with their memory and view, shader modules,
/// image layout barriers.
#include <cstdint>
#include <span>

#include "gpu/context.h"

namespace tender::render {

/// An image with its own memory and one view.
struct Image {
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
  VkExtent2D extent{0, 0};
  uint32_t mip_levels = 1;
};

/// What createImage makes.
struct ImageDesc {
  VkExtent2D extent{1, 1};
  VkFormat format = VK_FORMAT_R8G8B8A8_UNORM;
  VkImageUsageFlags usage = 0;
  VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_1_BIT;
  VkImageAspectFlags aspect = VK_IMAGE_ASPECT_COLOR_BIT;
  uint32_t mip_levels = 1;
};

/// Creates a 2-D image in device-local memory with a view of all its mip levels.
Image createImage(gpu::VulkanContext& ctx, const ImageDesc& desc);
/// Destroys an image, its view and its memory (no-op on an empty one).
void destroyImage(VkDevice device, Image& image);
/// Creates a shader module from SPIR-V words.
VkShaderModule createShaderModule(VkDevice device, std::span<const uint32_t> spirv);
/// Records a layout transition of mip levels [first_mip, first_mip + mips) with full stage masks.
void transitionImage(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect, VkImageLayout from,
                     VkImageLayout to, uint32_t first_mip = 0, uint32_t mips = VK_REMAINING_MIP_LEVELS);

} // namespace tender::render
