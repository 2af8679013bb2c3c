#pragma once
/// The scene renderer: the shadow pass, then the scene pass (background, paper, ground) resolved
/// into the caller's images (swapchain or offscreen), with the resources both read: one descriptor
/// set and uniform buffer per frame in flight, and the receipt texture.
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include <glm/glm.hpp>

#include "camera.h"
#include "core/params.h"
#include "paper_buffers.h"
#include "receipt.h"
#include "scene_pass.h"
#include "shadow_pass.h"
#include "vk_util.h"

namespace tender::render {

/// What the scene looks like this frame.
struct SceneView {
  OrbitCamera camera;
  float floor_y = -6.0f;
  glm::vec3 focus{0.0f, 0.0f, 0.0f}; ///< centre of the shadow map's box
  float extent = 10.0f;              ///< half size of the shadow map's box
  float scale = 1.0f;                ///< size of the scene (SimParams::view_scale): grid, light
  float ground = 5.0f;               ///< half size of the ground square
  /// A framed sheet (a scene of another size): the part of the view's height its length spans,
  /// the camera's target on its centre (followSheet); 0: a fixed view.
  float sheet_share = 0.0f;
};

/// The part of the view's height a framed sheet's length spans: a receipt that falls and lands
/// fills about a third of a 16:9 view, big enough to read its print.
inline constexpr float kFramedSheetShare = 0.5f;

/// The scene view of a parameter set: the spec's camera, the floor, a shadow box covering the
/// sheet and the ground; a scene of another size (SimParams::view_scale) frames its sheet.
SceneView defaultSceneView(const SimParams& params);

/// Aims a framed view's camera at the centre of the sheet's sample points (sheetSamples), where the
/// sheet is now; a fixed view (sheet_share 0) or no points leave it as it is.
void followSheet(SceneView& view, std::span<const glm::vec3> samples);

/// How the renderer's output is used.
struct RendererOptions {
  VkFormat color_format = VK_FORMAT_R8G8B8A8_UNORM;
  VkImageLayout final_layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL; ///< layout of the targets after the pass
  uint32_t frames = 2;                                               ///< frames in flight (uniform and set slots)
  uint32_t max_samples = 4;                                          ///< MSAA samples (lowered to what the device has)
  uint32_t shadow_size = RENDER_SHADOW_SIZE;                         ///< the shadow map's width and height
};

/// The renderer. Pipelines are built one by one (buildNext) so that a window can show progress.
class Renderer {
public:
  /// Creates both passes, the descriptor sets and the receipt texture (pipelines come later).
  Renderer(gpu::VulkanContext& ctx, const RendererOptions& options, const ReceiptImage& receipt);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Builds the next pipeline; returns the fraction built (1 when ready).
  float buildNext();
  /// Builds everything that is left.
  void buildAll();
  /// True when every pipeline is built.
  bool ready() const { return built_ == kPipelineCount; }

  /// (Re)creates the multisampled attachments and one framebuffer per target view.
  void setTargets(VkExtent2D extent, const std::vector<VkImageView>& views);
  /// Points frame slot `slot` at the buffers to draw the paper from.
  void setPaper(uint32_t slot, const PaperBuffers& buffers);
  /// Replaces the receipt texture (waits for the device to be idle).
  void setReceipt(const ReceiptImage& receipt);

  /// Records the shadow and scene passes into target `target` using frame slot `slot`; `overlay`
  /// records more draws (the HUD) inside the scene pass. Without pipelines (still building) the
  /// scene pass only clears to the background colour.
  void record(VkCommandBuffer cmd, uint32_t slot, uint32_t target, const SceneView& view,
              const std::function<void(VkCommandBuffer)>& overlay = {});

  /// The scene render pass (its subpass 0 is where overlays may draw too).
  VkRenderPass scenePass() const { return scene_.pass; }
  /// MSAA samples of the scene pass (an overlay pipeline must match them) and its target size.
  VkSampleCountFlagBits samples() const { return scene_.samples; }
  VkExtent2D extent() const { return scene_.extent; }

private:
  static constexpr uint32_t kPipelineCount = 1 + ScenePass::kPipelineCount;
  void createDescriptors();
  void createReceiptSampler();
  void uploadReceipt(const ReceiptImage& receipt);
  void writeUniforms(uint32_t slot, const SceneView& view);

  gpu::VulkanContext& ctx_;
  VkDevice dev_;
  RendererOptions options_;
  ShadowPass shadow_;
  ScenePass scene_;

  // Resources every pass reads: one descriptor set and uniform buffer per frame slot.
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  std::vector<VkDescriptorSet> sets_;
  std::vector<gpu::Buffer> uniforms_;
  std::vector<PaperBuffers> paper_;
  Image receipt_;
  VkSampler receipt_sampler_ = VK_NULL_HANDLE;
  uint32_t built_ = 0;
};

} // namespace tender::render
