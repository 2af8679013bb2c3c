#include "swapchain.h"

#include <algorithm>

namespace tender::demo {

VkFormat Swapchain::chooseFormat(VkPhysicalDevice pd, VkSurfaceKHR surface) {
  uint32_t n = 0;
  vkGetPhysicalDeviceSurfaceFormatsKHR(pd, surface, &n, nullptr);
  std::vector<VkSurfaceFormatKHR> formats(n);
  vkGetPhysicalDeviceSurfaceFormatsKHR(pd, surface, &n, formats.data());
  // The scene shades in display values (as the spec's page does), so a UNORM target.
  for (VkFormat want : {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM})
    for (auto& f : formats)
      if (f.format == want && f.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR) return want;
  return formats.empty() ? VK_FORMAT_B8G8R8A8_UNORM : formats[0].format;
}

Swapchain::Swapchain(gpu::VulkanContext& ctx, VkSurfaceKHR surface, bool vsync)
    : ctx_(ctx), surface_(surface), vsync_(vsync) {
  format_ = chooseFormat(ctx.physicalDevice(), surface);
}

Swapchain::~Swapchain() {
  destroyViews();
  if (swapchain_) vkDestroySwapchainKHR(ctx_.device(), swapchain_, nullptr);
}

void Swapchain::destroyViews() {
  for (VkImageView v : views_) vkDestroyImageView(ctx_.device(), v, nullptr);
  views_.clear();
}

bool Swapchain::recreate(VkExtent2D fb) {
  VkDevice dev = ctx_.device();
  VkSurfaceCapabilitiesKHR caps;
  VK_CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(ctx_.physicalDevice(), surface_, &caps));
  VkExtent2D extent = caps.currentExtent;
  if (extent.width == UINT32_MAX) {
    extent.width = std::clamp(fb.width, caps.minImageExtent.width, caps.maxImageExtent.width);
    extent.height = std::clamp(fb.height, caps.minImageExtent.height, caps.maxImageExtent.height);
  }
  if (extent.width == 0 || extent.height == 0) return false;

  uint32_t n = 0;
  vkGetPhysicalDeviceSurfacePresentModesKHR(ctx_.physicalDevice(), surface_, &n, nullptr);
  std::vector<VkPresentModeKHR> modes(n);
  vkGetPhysicalDeviceSurfacePresentModesKHR(ctx_.physicalDevice(), surface_, &n, modes.data());
  VkPresentModeKHR mode = VK_PRESENT_MODE_FIFO_KHR;
  if (!vsync_)
    for (VkPresentModeKHR m : {VK_PRESENT_MODE_MAILBOX_KHR, VK_PRESENT_MODE_IMMEDIATE_KHR})
      if (std::find(modes.begin(), modes.end(), m) != modes.end()) {
        mode = m;
        break;
      }

  uint32_t count = std::max(caps.minImageCount + 1, 3u);
  if (caps.maxImageCount > 0) count = std::min(count, caps.maxImageCount);
  VkSwapchainCreateInfoKHR ci{};
  ci.sType = VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR;
  ci.surface = surface_;
  ci.minImageCount = count;
  ci.imageFormat = format_;
  ci.imageColorSpace = VK_COLOR_SPACE_SRGB_NONLINEAR_KHR;
  ci.imageExtent = extent;
  ci.imageArrayLayers = 1;
  ci.imageUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  ci.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
  ci.preTransform = caps.currentTransform;
  ci.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
  ci.presentMode = mode;
  ci.clipped = VK_TRUE;
  ci.oldSwapchain = swapchain_;
  VkSwapchainKHR next = VK_NULL_HANDLE;
  VK_CHECK(vkCreateSwapchainKHR(dev, &ci, nullptr, &next));
  destroyViews();
  if (swapchain_) vkDestroySwapchainKHR(dev, swapchain_, nullptr);
  swapchain_ = next;
  extent_ = extent;

  vkGetSwapchainImagesKHR(dev, swapchain_, &n, nullptr);
  images_.resize(n);
  vkGetSwapchainImagesKHR(dev, swapchain_, &n, images_.data());
  for (VkImage img : images_) {
    VkImageViewCreateInfo vi{};
    vi.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
    vi.image = img;
    vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vi.format = format_;
    vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    VkImageView v = VK_NULL_HANDLE;
    VK_CHECK(vkCreateImageView(dev, &vi, nullptr, &v));
    views_.push_back(v);
  }
  return true;
}

} // namespace tender::demo
