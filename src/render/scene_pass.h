#pragma once
/// The scene pass: background gradient, paper and translucent ground into a multisampled target,
/// resolved into the caller's images (swapchain or offscreen).
#include <functional>
#include <vector>

#include "paper_buffers.h"
#include "vk_util.h"

namespace tender::render {

/// Resources of the scene pass.
struct ScenePass {
  VkRenderPass pass = VK_NULL_HANDLE;
  VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_1_BIT;
  VkFormat color_format = VK_FORMAT_UNDEFINED;
  VkPipeline background = VK_NULL_HANDLE, paper = VK_NULL_HANDLE, ground = VK_NULL_HANDLE;
  Image color, depth;                      ///< multisampled attachments (color only with MSAA)
  std::vector<VkFramebuffer> framebuffers; ///< one per target view
  VkExtent2D extent{0, 0};

  /// Number of pipelines buildPipeline builds.
  static constexpr uint32_t kPipelineCount = 3;

  /// Creates the render pass; the targets end in `final_layout`.
  void create(VkDevice dev, VkFormat format, VkImageLayout final_layout, VkSampleCountFlagBits sample_count);
  /// Builds pipeline `which`: 0 background, 1 paper, 2 ground.
  void buildPipeline(VkDevice dev, VkPipelineLayout layout, uint32_t which);
  /// (Re)creates the attachments and one framebuffer per target view.
  void setTargets(gpu::VulkanContext& ctx, VkExtent2D size, const std::vector<VkImageView>& views);
  /// Destroys the attachments and framebuffers.
  void destroyTargets(VkDevice dev);
  /// Records the pass into target `target`: the background, the paper (when `paper` is set; the
  /// scene set is bound), then the ground over what lies below it, then `overlay`.
  void record(VkCommandBuffer cmd, uint32_t target, const PaperBuffers* paper,
              const std::function<void(VkCommandBuffer)>& overlay) const;
  /// Destroys every resource (no-op on an empty pass).
  void destroy(VkDevice dev);
};

} // namespace tender::render
