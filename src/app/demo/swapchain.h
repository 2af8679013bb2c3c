#pragma once
/// The window's swapchain: images, views, recreation on resize.
#include <vector>

#include "gpu/context.h"

namespace tender::demo {

/// The swapchain of the demo window, with one view per image.
class Swapchain {
public:
  /// A swapchain for `surface`; vsync picks FIFO, otherwise mailbox or immediate when available.
  Swapchain(gpu::VulkanContext& ctx, VkSurfaceKHR surface, bool vsync);
  ~Swapchain();
  Swapchain(const Swapchain&) = delete;
  Swapchain& operator=(const Swapchain&) = delete;

  /// (Re)creates the swapchain for a framebuffer of this size; false when the size is 0 (minimised).
  bool recreate(VkExtent2D framebuffer);

  /// The current swapchain, its colour format, size, image views and image count.
  VkSwapchainKHR handle() const { return swapchain_; }
  VkFormat format() const { return format_; }
  VkExtent2D extent() const { return extent_; }
  const std::vector<VkImageView>& views() const { return views_; }
  uint32_t imageCount() const { return uint32_t(images_.size()); }

  /// Colour format the swapchain will use (known before the first recreate).
  static VkFormat chooseFormat(VkPhysicalDevice pd, VkSurfaceKHR surface);

private:
  void destroyViews();
  gpu::VulkanContext& ctx_;
  VkSurfaceKHR surface_;
  bool vsync_;
  VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  VkExtent2D extent_{0, 0};
  std::vector<VkImage> images_;
  std::vector<VkImageView> views_;
};

} // namespace tender::demo
