#include "offscreen.h"

#include "core/output.h"
#include "gpu/barriers.h"

#include <cstring>

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

namespace tender::render {

OffscreenTarget::OffscreenTarget(gpu::VulkanContext& ctx, Renderer& renderer, uint32_t width, uint32_t height)
    : ctx_(ctx), renderer_(renderer) {
  ImageDesc d;
  d.extent = {width, height};
  d.format = kFormat;
  d.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  image_ = createImage(ctx, d);
  readback_ = ctx.createHostBuffer(VkDeviceSize(width) * height * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  renderer.setTargets(d.extent, {image_.view});
}

OffscreenTarget::~OffscreenTarget() {
  vkQueueWaitIdle(ctx_.queue()); // unchecked: may run while a Vulkan error unwinds
  destroyImage(ctx_.device(), image_);
  ctx_.destroyBuffer(readback_);
}

Picture OffscreenTarget::render(const SceneView& view) {
  const VkExtent2D e = image_.extent;
  ctx_.submitOnce([&](VkCommandBuffer cmd) {
    renderer_.record(cmd, 0, 0, view);
    // The scene pass leaves the image in TRANSFER_SRC_OPTIMAL.
    VkBufferImageCopy copy{};
    copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    copy.imageExtent = {e.width, e.height, 1};
    vkCmdCopyImageToBuffer(cmd, image_.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback_.buffer, 1, &copy);
    gpu::transferToHost(cmd);
  });
  Picture p;
  p.width = e.width;
  p.height = e.height;
  p.rgba.resize(size_t(e.width) * e.height * 4);
  std::memcpy(p.rgba.data(), readback_.mapped, p.rgba.size());
  return p;
}

std::string encodePng(const Picture& picture) {
  std::string bytes;
  stbi_write_png_to_func(
      [](void* context, void* data, int size) {
        static_cast<std::string*>(context)->append(static_cast<char*>(data), size_t(size));
      },
      &bytes, int(picture.width), int(picture.height), 4, picture.rgba.data(), int(picture.width * 4));
  return bytes;
}

std::optional<std::string> writePng(const std::string& path, const Picture& picture) {
  return writeFileAtomically(path, encodePng(picture));
}

Picture readPng(const std::string& path) {
  int w = 0, h = 0, n = 0;
  unsigned char* data = stbi_load(path.c_str(), &w, &h, &n, 4);
  Picture p;
  if (!data) return p;
  p.width = uint32_t(w);
  p.height = uint32_t(h);
  p.rgba.assign(data, data + size_t(w) * size_t(h) * 4);
  stbi_image_free(data);
  return p;
}

} // namespace tender::render
