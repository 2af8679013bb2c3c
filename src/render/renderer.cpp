#include "renderer.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <glm/gtc/matrix_transform.hpp>

#include "core/sheet.h"

namespace tender::render {
namespace {

// sRGB hex colour as a display-referred RGB triple (the scene is shaded in display values, as
// the spec's three.js r128 page is).
glm::vec4 hexColor(uint32_t rgb, float w = 1.0f) {
  return {float((rgb >> 16) & 255) / 255.0f, float((rgb >> 8) & 255) / 255.0f, float(rgb & 255) / 255.0f, w};
}

VkSampleCountFlagBits pickSamples(const VkPhysicalDeviceProperties& p, uint32_t max) {
  VkSampleCountFlags ok = p.limits.framebufferColorSampleCounts & p.limits.framebufferDepthSampleCounts;
  for (uint32_t s = std::min(max, 8u); s > 1; s >>= 1)
    if (ok & s) return VkSampleCountFlagBits(s);
  return VK_SAMPLE_COUNT_1_BIT;
}

} // namespace

SceneView defaultSceneView(const SimParams& p) {
  SceneView v;
  v.floor_y = p.floor_y;
  const float s = p.view_scale;
  const SheetPlacement at = sheetPlacement(p);
  const float top = at.top;
  v.scale = s;
  v.focus = glm::vec3(0.0f, 0.5f * (top + p.floor_y), 0.0f);
  v.extent = std::max(8.0f * s, 0.5f * (top - p.floor_y) + 3.0f * s);
  if (s != 1.0f) {
    // A scene of another size: the spec's direction of view, scaled, on the sheet's centre, from
    // where its length spans kFramedSheetShare of the view's height; the shadow's box and the
    // ground cover the fall below it (and halfway along a tilted sheet's lean).
    v.camera.setScale(s);
    v.sheet_share = kFramedSheetShare;
    const glm::vec3 centre(0.0f, top - 0.5f * at.length * at.down, -0.5f * at.length * at.back);
    const float half_fov = glm::radians(OrbitCamera::kFovDegrees) * 0.5f;
    const float distance = std::max(at.length, s) / (v.sheet_share * 2.0f * std::tan(half_fov));
    v.camera.lookAt(centre + glm::normalize(glm::vec3(4.0f, 10.0f, 9.0f)) * distance, centre);
    v.focus = glm::vec3(0.0f, 0.5f * (top + p.floor_y), -0.5f * at.length * at.back);
    v.ground = v.extent; // as far as the shadow reaches
  }
  return v;
}

void followSheet(SceneView& view, std::span<const glm::vec3> samples) {
  if (view.sheet_share > 0.0f && !samples.empty()) view.camera.setTarget(centreOf(samples));
}

Renderer::Renderer(gpu::VulkanContext& ctx, const RendererOptions& options, const ReceiptImage& receipt)
    : ctx_(ctx), dev_(ctx.device()), options_(options) {
  shadow_.create(ctx, options.shadow_size);
  scene_.create(dev_, options.color_format, options.final_layout, pickSamples(ctx.properties(), options.max_samples));
  createReceiptSampler();
  uploadReceipt(receipt);
  createDescriptors();
}

Renderer::~Renderer() {
  vkDeviceWaitIdle(dev_);
  scene_.destroy(dev_);
  shadow_.destroy(dev_);
  destroyImage(dev_, receipt_);
  vkDestroySampler(dev_, receipt_sampler_, nullptr);
  for (auto& u : uniforms_) ctx_.destroyBuffer(u);
  vkDestroyDescriptorPool(dev_, pool_, nullptr);
  vkDestroyPipelineLayout(dev_, layout_, nullptr);
  vkDestroyDescriptorSetLayout(dev_, set_layout_, nullptr);
}

void Renderer::createReceiptSampler() {
  VkSamplerCreateInfo r{};

  r.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
  r.magFilter = r.minFilter = VK_FILTER_LINEAR;
  r.mipmapMode = VK_SAMPLER_MIPMAP_MODE_LINEAR;
  r.addressModeU = r.addressModeV = r.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  r.maxLod = VK_LOD_CLAMP_NONE;
  // Anisotropic filtering keeps the print sharp on a sheet seen edge-on (the context enables the
  // feature whenever the device has it).
  VkPhysicalDeviceFeatures features;
  vkGetPhysicalDeviceFeatures(ctx_.physicalDevice(), &features);
  if (features.samplerAnisotropy) {
    r.anisotropyEnable = VK_TRUE;
    r.maxAnisotropy = std::min(8.0f, ctx_.properties().limits.maxSamplerAnisotropy);
  }
  VK_CHECK(vkCreateSampler(dev_, &r, nullptr, &receipt_sampler_));
}

void Renderer::uploadReceipt(const ReceiptImage& receipt) {
  // Mip chain down to 1x1: the text stays legible when the sheet is small on screen.
  uint32_t mips = 1;
  for (uint32_t s = std::max(receipt.width, receipt.height); s > 1; s >>= 1) ++mips;
  ImageDesc d;
  d.extent = {receipt.width, receipt.height};
  d.format = VK_FORMAT_R8G8B8A8_UNORM;
  d.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  d.mip_levels = mips;
  receipt_ = createImage(ctx_, d);
  gpu::Buffer staging = ctx_.createHostBuffer(receipt.rgba.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  std::memcpy(staging.mapped, receipt.rgba.data(), receipt.rgba.size());
  ctx_.submitOnce([&](VkCommandBuffer cmd) {
    VkImage img = receipt_.image;
    transitionImage(cmd, img, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                    VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
    VkBufferImageCopy copy{};
    copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    copy.imageExtent = {receipt.width, receipt.height, 1};
    vkCmdCopyBufferToImage(cmd, staging.buffer, img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
    int32_t w = int32_t(receipt.width), h = int32_t(receipt.height);
    for (uint32_t m = 1; m < mips; ++m) {
      transitionImage(cmd, img, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                      VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, m - 1, 1);
      VkImageBlit blit{};
      blit.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, m - 1, 0, 1};
      blit.srcOffsets[1] = {w, h, 1};
      w = std::max(w / 2, 1);
      h = std::max(h / 2, 1);
      blit.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, m, 0, 1};
      blit.dstOffsets[1] = {w, h, 1};
      vkCmdBlitImage(cmd, img, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                     &blit, VK_FILTER_LINEAR);
    }
    transitionImage(cmd, img, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                    VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, 0, mips - 1);
    transitionImage(cmd, img, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                    VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, mips - 1, 1);
  });
  ctx_.destroyBuffer(staging);
}

void Renderer::setReceipt(const ReceiptImage& receipt) {
  vkDeviceWaitIdle(dev_);
  destroyImage(dev_, receipt_);
  uploadReceipt(receipt);
  for (VkDescriptorSet set : sets_) {
    VkDescriptorImageInfo ii{receipt_sampler_, receipt_.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    VkWriteDescriptorSet w{};
    w.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    w.dstSet = set;
    w.dstBinding = RENDER_BIND_RECEIPT;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    w.pImageInfo = &ii;
    vkUpdateDescriptorSets(dev_, 1, &w, 0, nullptr);
  }
}

void Renderer::createDescriptors() {
  const VkShaderStageFlags vf = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
  VkDescriptorSetLayoutBinding b[7] = {
      {RENDER_BIND_SCENE, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, vf, nullptr},
      {RENDER_BIND_RECEIPT, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_FRAGMENT_BIT, nullptr},
      {RENDER_BIND_SHADOW, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_FRAGMENT_BIT, nullptr},
      {RENDER_BIND_POS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT, nullptr},
      {RENDER_BIND_NORMAL, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT, nullptr},
      {RENDER_BIND_UV, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT, nullptr},
      {RENDER_BIND_TRIANGLES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT, nullptr},
  };
  VkDescriptorSetLayoutCreateInfo lci{};
  lci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  lci.bindingCount = 7;
  lci.pBindings = b;
  VK_CHECK(vkCreateDescriptorSetLayout(dev_, &lci, nullptr, &set_layout_));
  VkPipelineLayoutCreateInfo pci{};
  pci.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  pci.setLayoutCount = 1;
  pci.pSetLayouts = &set_layout_;
  VK_CHECK(vkCreatePipelineLayout(dev_, &pci, nullptr, &layout_));

  const uint32_t n = options_.frames;
  VkDescriptorPoolSize sizes[3] = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, n},
                                   {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 2 * n},
                                   {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 4 * n}};
  VkDescriptorPoolCreateInfo dp{};
  dp.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  dp.maxSets = n;
  dp.poolSizeCount = 3;
  dp.pPoolSizes = sizes;
  VK_CHECK(vkCreateDescriptorPool(dev_, &dp, nullptr, &pool_));
  sets_ = gpu::allocateDescriptorSets(dev_, pool_, set_layout_, n);
  uniforms_.resize(n);
  paper_.resize(n);
  for (uint32_t i = 0; i < n; ++i) {
    uniforms_[i] = ctx_.createHostBuffer(sizeof(shaderio::SceneUniforms), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
    VkDescriptorBufferInfo bi{uniforms_[i].buffer, 0, sizeof(shaderio::SceneUniforms)};
    VkDescriptorImageInfo ri{receipt_sampler_, receipt_.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    VkDescriptorImageInfo si{shadow_.sampler, shadow_.map.view, VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL};
    VkWriteDescriptorSet w[3]{};
    for (auto& x : w) {
      x.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
      x.dstSet = sets_[i];
      x.descriptorCount = 1;
    }
    w[0].dstBinding = RENDER_BIND_SCENE;
    w[0].descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
    w[0].pBufferInfo = &bi;
    w[1].dstBinding = RENDER_BIND_RECEIPT;
    w[1].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    w[1].pImageInfo = &ri;
    w[2].dstBinding = RENDER_BIND_SHADOW;
    w[2].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    w[2].pImageInfo = &si;
    vkUpdateDescriptorSets(dev_, 3, w, 0, nullptr);
  }
}

void Renderer::setPaper(uint32_t slot, const PaperBuffers& p) {
  paper_[slot] = p;
  VkDescriptorBufferInfo bi[4] = {{p.pos, 0, VK_WHOLE_SIZE},
                                  {p.normal, 0, VK_WHOLE_SIZE},
                                  {p.uv, 0, VK_WHOLE_SIZE},
                                  {p.triangles, 0, VK_WHOLE_SIZE}};
  const uint32_t binding[4] = {RENDER_BIND_POS, RENDER_BIND_NORMAL, RENDER_BIND_UV, RENDER_BIND_TRIANGLES};
  VkWriteDescriptorSet w[4]{};
  for (int i = 0; i < 4; ++i) {
    w[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    w[i].dstSet = sets_[slot];
    w[i].dstBinding = binding[i];
    w[i].descriptorCount = 1;
    w[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    w[i].pBufferInfo = &bi[i];
  }
  vkUpdateDescriptorSets(dev_, 4, w, 0, nullptr);
}

float Renderer::buildNext() {
  if (built_ == 0)
    shadow_.buildPipeline(dev_, layout_);
  else if (built_ < kPipelineCount)
    scene_.buildPipeline(dev_, layout_, built_ - 1);
  built_ = std::min(built_ + 1, kPipelineCount);
  return float(built_) / float(kPipelineCount);
}

void Renderer::buildAll() {
  while (!ready()) buildNext();
}

void Renderer::setTargets(VkExtent2D extent, const std::vector<VkImageView>& views) {
  scene_.setTargets(ctx_, extent, views);
}

void Renderer::writeUniforms(uint32_t slot, const SceneView& view) {
  shaderio::SceneUniforms u{};
  float aspect = float(scene_.extent.width) / float(std::max(scene_.extent.height, 1u));
  u.view_proj = view.camera.projection(aspect) * view.camera.view();
  // Directional light from the upper right of the start view.
  const glm::vec3 to_light = glm::normalize(glm::vec3(7.0f, 10.0f, 6.0f));
  glm::mat4 light_view =
      glm::lookAtRH(view.focus + to_light * (40.0f * view.scale), view.focus, glm::vec3(0.0f, 1.0f, 0.0f));
  glm::mat4 light_proj =
      glm::orthoRH_ZO(-view.extent, view.extent, -view.extent, view.extent, view.scale, 80.0f * view.scale);
  u.light_view_proj = light_proj * light_view;
  u.eye = glm::vec4(view.camera.eye(), 1.0f);
  u.light_dir = glm::vec4(to_light, 0.8f);
  u.ambient = glm::vec4(0.6f, 0.6f, 0.6f, 1.0f);
  u.paper = glm::vec4(1.0f, 1.0f, 1.0f, 0.7f);
  u.ground = hexColor(0xd0ccc8, 0.5f);
  u.bg_top = hexColor(0xe8e4e0);
  u.bg_bottom = hexColor(0xd8d4d0);
  u.floor = glm::vec4(view.floor_y, view.ground, view.scale, 1.0f / float(shadow_.size));
  std::memcpy(uniforms_[slot].mapped, &u, sizeof(u));
}

void Renderer::record(VkCommandBuffer cmd, uint32_t slot, uint32_t target, const SceneView& view,
                      const std::function<void(VkCommandBuffer)>& overlay) {
  writeUniforms(slot, view);
  const PaperBuffers& paper = paper_[slot];
  const bool draw = ready() && paper.pos != VK_NULL_HANDLE;
  if (draw) {
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, layout_, 0, 1, &sets_[slot], 0, nullptr);
    shadow_.record(cmd, paper);
  }
  scene_.record(cmd, target, draw ? &paper : nullptr, overlay);
}

} // namespace tender::render
