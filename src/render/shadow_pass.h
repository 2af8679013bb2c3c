#pragma once
/// The shadow pass: a depth map of the paper seen from the light (RENDER_SHADOW_SIZE², 2048², or
/// smaller where the renderer is asked to: RendererOptions::shadow_size), orthographic, sampled
/// with PCF by the scene pass.
#include "paper_buffers.h"
#include "vk_util.h"

namespace tender::render {

/// Resources of the shadow pass.
struct ShadowPass {
  Image map; ///< depth, DEPTH_STENCIL_READ_ONLY between passes
  VkRenderPass pass = VK_NULL_HANDLE;
  VkFramebuffer framebuffer = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkSampler sampler = VK_NULL_HANDLE; ///< comparison sampler (lit where depth <= map)
  uint32_t size = 0;                  ///< the map's width and height

  /// Creates the render pass, the map of `size`² (cleared to "fully lit") and its sampler.
  void create(gpu::VulkanContext& ctx, uint32_t size);
  /// Builds the depth-only pipeline (slope-scaled depth bias against acne).
  void buildPipeline(VkDevice dev, VkPipelineLayout layout);
  /// Records the pass: the paper's live triangles from the light (the scene set is bound).
  void record(VkCommandBuffer cmd, const PaperBuffers& paper) const;
  /// Destroys every resource (no-op on an empty pass).
  void destroy(VkDevice dev);
};

} // namespace tender::render
