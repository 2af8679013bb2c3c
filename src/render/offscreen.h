#pragma once
/// Rendering without a window: the scene resolved into an offscreen image and read back.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "renderer.h"

namespace tender::render {

/// An RGBA8 picture, rows top to bottom.
struct Picture {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgba;
};

/// An offscreen colour target the renderer draws into, and its read-back.
class OffscreenTarget {
public:
  /// Format of offscreen renderers (RendererOptions::color_format).
  static constexpr VkFormat kFormat = VK_FORMAT_R8G8B8A8_UNORM;
  /// A width x height target; points the renderer at it.
  OffscreenTarget(gpu::VulkanContext& ctx, Renderer& renderer, uint32_t width, uint32_t height);
  ~OffscreenTarget();
  OffscreenTarget(const OffscreenTarget&) = delete;
  OffscreenTarget& operator=(const OffscreenTarget&) = delete;

  /// Renders one frame (frame slot 0) and returns the picture.
  Picture render(const SceneView& view);

private:
  gpu::VulkanContext& ctx_;
  Renderer& renderer_;
  Image image_;
  gpu::Buffer readback_;
};

/// The picture encoded as PNG bytes.
std::string encodePng(const Picture& picture);
/// Writes a picture as PNG atomically (see core/output.h); returns the error on failure.
std::optional<std::string> writePng(const std::string& path, const Picture& picture);
/// Reads a PNG as RGBA8; returns an empty picture when it cannot be read.
Picture readPng(const std::string& path);

} // namespace tender::render
