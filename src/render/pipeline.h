#pragma once
/// Graphics pipelines of the render passes: one helper that builds a pipeline from the few
/// states that differ between passes, and the dynamic viewport.
#include <vulkan/vulkan.h>

namespace tender::render {

/// Depth format of the scene pass and of the shadow map.
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

/// Fixed-function state of one graphics pipeline (no vertex input: every pass pulls its vertices).
struct PipelineDesc {
  const char* vert = nullptr;
  const char* frag = nullptr; ///< nullptr: depth only
  VkRenderPass pass = VK_NULL_HANDLE;
  VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_1_BIT;
  bool depth_test = true, depth_write = true, blend = false, depth_bias = false;
};

/// Creates a pipeline from the embedded render shaders; triangles, no culling (double-sided paper).
VkPipeline createPipeline(VkDevice dev, VkPipelineLayout layout, const PipelineDesc& desc);
/// Sets the dynamic viewport and scissor to the whole extent.
void setViewport(VkCommandBuffer cmd, VkExtent2D extent);

} // namespace tender::render
