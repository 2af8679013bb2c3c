#include "shadow_pass.h"

#include "pipeline.h"

namespace tender::render {

namespace {

/// The shadow pass: one depth attachment, left readable by the scene pass.
VkRenderPass createDepthPass(VkDevice dev) {
  VkAttachmentDescription a{};
  a.format = kDepthFormat;
  a.samples = VK_SAMPLE_COUNT_1_BIT;
  a.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  a.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  a.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  a.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  a.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  a.finalLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL;
  VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  VkSubpassDescription sp{};
  sp.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  sp.pDepthStencilAttachment = &ref;
  VkSubpassDependency deps[2]{};
  // The previous frame's scene pass finished sampling the map before it is cleared.
  deps[0].srcSubpass = VK_SUBPASS_EXTERNAL;
  deps[0].dstSubpass = 0;
  deps[0].srcStageMask = VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT;
  deps[0].dstStageMask = VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
  deps[0].srcAccessMask = VK_ACCESS_SHADER_READ_BIT;
  deps[0].dstAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT;
  // The depth writes are visible to the scene pass' fragment shaders.
  deps[1].srcSubpass = 0;
  deps[1].dstSubpass = VK_SUBPASS_EXTERNAL;
  deps[1].srcStageMask = VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
  deps[1].dstStageMask = VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT;
  deps[1].srcAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  deps[1].dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
  VkRenderPassCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO;
  ci.attachmentCount = 1;
  ci.pAttachments = &a;
  ci.subpassCount = 1;
  ci.pSubpasses = &sp;
  ci.dependencyCount = 2;
  ci.pDependencies = deps;
  VkRenderPass pass = VK_NULL_HANDLE;
  VK_CHECK(vkCreateRenderPass(dev, &ci, nullptr, &pass));
  return pass;
}

} // namespace

void ShadowPass::create(gpu::VulkanContext& ctx, uint32_t map_size) {
  size = map_size;
  VkDevice dev = ctx.device();
  pass = createDepthPass(dev);

  // Comparison sampler; bilinear comparisons where the format allows them.
  VkFormatProperties fp;
  vkGetPhysicalDeviceFormatProperties(ctx.physicalDevice(), kDepthFormat, &fp);
  const bool linear = fp.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT;
  VkSamplerCreateInfo s{};
  s.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
  s.magFilter = s.minFilter = linear ? VK_FILTER_LINEAR : VK_FILTER_NEAREST;
  s.addressModeU = s.addressModeV = s.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER;
  s.borderColor = VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE;
  s.compareEnable = VK_TRUE;
  s.compareOp = VK_COMPARE_OP_LESS_OR_EQUAL;
  s.maxLod = 0.0f;
  VK_CHECK(vkCreateSampler(dev, &s, nullptr, &sampler));

  // The map and its framebuffer.
  ImageDesc d;
  d.extent = {size, size};
  d.format = kDepthFormat;
  d.usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  d.aspect = VK_IMAGE_ASPECT_DEPTH_BIT;
  map = createImage(ctx, d);
  VkFramebufferCreateInfo fb{};
  fb.sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO;
  fb.renderPass = pass;
  fb.attachmentCount = 1;
  fb.pAttachments = &map.view;
  fb.width = fb.height = size;
  fb.layers = 1;
  VK_CHECK(vkCreateFramebuffer(dev, &fb, nullptr, &framebuffer));
  // Until the first shadow pass, the map reads as fully lit.
  ctx.submitOnce([&](VkCommandBuffer cmd) {
    transitionImage(cmd, map.image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                    VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
    VkClearDepthStencilValue one{1.0f, 0};
    VkImageSubresourceRange range{VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
    vkCmdClearDepthStencilImage(cmd, map.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &one, 1, &range);
    transitionImage(cmd, map.image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                    VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL);
  });
}

void ShadowPass::buildPipeline(VkDevice dev, VkPipelineLayout layout) {
  PipelineDesc d;
  d.vert = "shadow.vert";
  d.pass = pass;
  d.depth_bias = true;
  pipeline = createPipeline(dev, layout, d);
}

void ShadowPass::record(VkCommandBuffer cmd, const PaperBuffers& paper) const {
  VkClearValue clear_depth{};
  clear_depth.depthStencil = {1.0f, 0};
  VkRenderPassBeginInfo rb{};
  rb.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
  rb.renderPass = pass;
  rb.framebuffer = framebuffer;
  rb.renderArea = {{0, 0}, {size, size}};
  rb.clearValueCount = 1;
  rb.pClearValues = &clear_depth;
  vkCmdBeginRenderPass(cmd, &rb, VK_SUBPASS_CONTENTS_INLINE);
  setViewport(cmd, {size, size});
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
  vkCmdDrawIndirect(cmd, paper.draw_args, paper.draw_args_offset, 1, 0);
  vkCmdEndRenderPass(cmd);
}

void ShadowPass::destroy(VkDevice dev) {
  if (pipeline) vkDestroyPipeline(dev, pipeline, nullptr);
  if (framebuffer) vkDestroyFramebuffer(dev, framebuffer, nullptr);
  destroyImage(dev, map);
  if (sampler) vkDestroySampler(dev, sampler, nullptr);
  if (pass) vkDestroyRenderPass(dev, pass, nullptr);
  *this = ShadowPass{};
}

} // namespace tender::render
