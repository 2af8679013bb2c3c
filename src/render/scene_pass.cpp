#include "scene_pass.h"

#include "pipeline.h"

namespace tender::render {

void ScenePass::create(VkDevice dev, VkFormat format, VkImageLayout final_layout, VkSampleCountFlagBits sample_count) {
  color_format = format;
  samples = sample_count;
  const bool msaa = samples != VK_SAMPLE_COUNT_1_BIT;
  VkAttachmentDescription a[3]{};
  a[0].format = color_format;
  a[0].samples = samples;
  a[0].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  a[0].storeOp = msaa ? VK_ATTACHMENT_STORE_OP_DONT_CARE : VK_ATTACHMENT_STORE_OP_STORE;
  a[0].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  a[0].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  a[0].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  a[0].finalLayout = msaa ? VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL : final_layout;
  a[1] = a[0];
  a[1].format = kDepthFormat;
  a[1].storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  a[1].finalLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
  a[2] = a[0];
  a[2].samples = VK_SAMPLE_COUNT_1_BIT;
  a[2].loadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  a[2].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  a[2].finalLayout = final_layout;
  VkAttachmentReference color_ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  VkAttachmentReference depth_ref{1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  VkAttachmentReference resolve_ref{2, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  VkSubpassDescription sp{};
  sp.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  sp.colorAttachmentCount = 1;
  sp.pColorAttachments = &color_ref;
  sp.pResolveAttachments = msaa ? &resolve_ref : nullptr;
  sp.pDepthStencilAttachment = &depth_ref;
  VkSubpassDependency deps[2]{};
  // Earlier uses of the attachments (the previous frame, a present, a copy) come first.
  deps[0].srcSubpass = VK_SUBPASS_EXTERNAL;
  deps[0].dstSubpass = 0;
  deps[0].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT |
                         VK_PIPELINE_STAGE_TRANSFER_BIT;
  deps[0].dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                         VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
  deps[0].srcAccessMask =
      VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT;
  deps[0].dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_COLOR_ATTACHMENT_READ_BIT |
                          VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT;
  // The resolved image is read afterwards by a copy or by an overlay pass.
  deps[1].srcSubpass = 0;
  deps[1].dstSubpass = VK_SUBPASS_EXTERNAL;
  deps[1].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  deps[1].dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  deps[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  deps[1].dstAccessMask =
      VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  VkRenderPassCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO;
  ci.attachmentCount = msaa ? 3 : 2;
  ci.pAttachments = a;
  ci.subpassCount = 1;
  ci.pSubpasses = &sp;
  ci.dependencyCount = 2;
  ci.pDependencies = deps;
  VK_CHECK(vkCreateRenderPass(dev, &ci, nullptr, &pass));
}

void ScenePass::buildPipeline(VkDevice dev, VkPipelineLayout layout, uint32_t which) {
  PipelineDesc d;
  d.pass = pass;
  d.samples = samples;
  if (which == 0) {
    d.vert = "background.vert";
    d.frag = "background.frag";
    d.depth_test = d.depth_write = false;
    background = createPipeline(dev, layout, d);
  } else if (which == 1) {
    d.vert = "paper.vert";
    d.frag = "paper.frag";
    paper = createPipeline(dev, layout, d);
  } else {
    // Translucent: tested against the paper, blended over it, writing no depth.
    d.vert = "ground.vert";
    d.frag = "ground.frag";
    d.blend = true;
    d.depth_write = false;
    ground = createPipeline(dev, layout, d);
  }
}

void ScenePass::destroyTargets(VkDevice dev) {
  for (VkFramebuffer fb : framebuffers) vkDestroyFramebuffer(dev, fb, nullptr);
  framebuffers.clear();
  destroyImage(dev, color);
  destroyImage(dev, depth);
}

void ScenePass::setTargets(gpu::VulkanContext& ctx, VkExtent2D size, const std::vector<VkImageView>& views) {
  destroyTargets(ctx.device());
  extent = size;
  const bool msaa = samples != VK_SAMPLE_COUNT_1_BIT;
  if (msaa) {
    ImageDesc c;
    c.extent = size;
    c.format = color_format;
    c.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSIENT_ATTACHMENT_BIT;
    c.samples = samples;
    color = createImage(ctx, c);
  }
  ImageDesc d;
  d.extent = size;
  d.format = kDepthFormat;
  d.usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSIENT_ATTACHMENT_BIT;
  d.samples = samples;
  d.aspect = VK_IMAGE_ASPECT_DEPTH_BIT;
  depth = createImage(ctx, d);
  for (VkImageView target : views) {
    VkImageView att[3] = {msaa ? color.view : target, depth.view, target};
    VkFramebufferCreateInfo fb{};
    fb.sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO;
    fb.renderPass = pass;
    fb.attachmentCount = msaa ? 3 : 2;
    fb.pAttachments = att;
    fb.width = size.width;
    fb.height = size.height;
    fb.layers = 1;
    VkFramebuffer f = VK_NULL_HANDLE;
    VK_CHECK(vkCreateFramebuffer(ctx.device(), &fb, nullptr, &f));
    framebuffers.push_back(f);
  }
}

void ScenePass::record(VkCommandBuffer cmd, uint32_t target, const PaperBuffers* paper_buffers,
                       const std::function<void(VkCommandBuffer)>& overlay) const {
  VkClearValue clear[2]{};
  clear[0].color = {{0xe0 / 255.0f, 0xdc / 255.0f, 0xd8 / 255.0f, 1.0f}}; // between the gradient's ends
  clear[1].depthStencil = {1.0f, 0};
  VkRenderPassBeginInfo rb{};
  rb.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
  rb.renderPass = pass;
  rb.framebuffer = framebuffers[target];
  rb.renderArea = {{0, 0}, extent};
  rb.clearValueCount = 2;
  rb.pClearValues = clear;
  vkCmdBeginRenderPass(cmd, &rb, VK_SUBPASS_CONTENTS_INLINE);
  setViewport(cmd, extent);
  if (paper_buffers) {
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, background);
    vkCmdDraw(cmd, 3, 1, 0, 0);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, paper);
    vkCmdDrawIndirect(cmd, paper_buffers->draw_args, paper_buffers->draw_args_offset, 1, 0);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, ground);
    vkCmdDraw(cmd, 6, 1, 0, 0);
  }
  if (overlay) overlay(cmd);
  vkCmdEndRenderPass(cmd);
}

void ScenePass::destroy(VkDevice dev) {
  destroyTargets(dev);
  for (VkPipeline p : {background, paper, ground})
    if (p) vkDestroyPipeline(dev, p, nullptr);
  if (pass) vkDestroyRenderPass(dev, pass, nullptr);
  *this = ScenePass{};
}

} // namespace tender::render
