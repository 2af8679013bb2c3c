// VulkanContext's buffers, one-off submissions and read-backs, and descriptor-set allocation
// (context.h); context.cpp creates the instance and the device.
#include <algorithm>
#include <cstring>

#include "barriers.h"
#include "context.h"

namespace tender::gpu {

uint32_t VulkanContext::findMemoryType(uint32_t type_bits, VkMemoryPropertyFlags flags) const {
  for (uint32_t i = 0; i < mem_props_.memoryTypeCount; ++i)
    if ((type_bits & (1u << i)) && (mem_props_.memoryTypes[i].propertyFlags & flags) == flags) return i;
  return UINT32_MAX;
}

Buffer VulkanContext::createBuffer(VkDeviceSize size, VkBufferUsageFlags usage, VkMemoryPropertyFlags flags, bool map) {
  Buffer b;
  b.size = std::max<VkDeviceSize>(size, 16);
  VkBufferCreateInfo bci{};
  bci.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  bci.size = b.size;
  bci.usage = usage;
  bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VK_CHECK(vkCreateBuffer(device_, &bci, nullptr, &b.buffer));
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device_, b.buffer, &req);
  uint32_t type = findMemoryType(req.memoryTypeBits, flags);
  if (type == UINT32_MAX && (flags & VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT))
    type = findMemoryType(req.memoryTypeBits, 0); // no device-local type: take any
  if (type == UINT32_MAX) vkCheckFailed(VK_ERROR_OUT_OF_DEVICE_MEMORY, "findMemoryType", __FILE__, __LINE__);
  VkMemoryAllocateInfo mai{};
  mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = type;
  VkMemoryAllocateFlagsInfo flags_info{};
  flags_info.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO;
  flags_info.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  if (usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) mai.pNext = &flags_info;
  VK_CHECK(vkAllocateMemory(device_, &mai, nullptr, &b.memory));
  VK_CHECK(vkBindBufferMemory(device_, b.buffer, b.memory, 0));
  if (map) VK_CHECK(vkMapMemory(device_, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped));
  return b;
}

Buffer VulkanContext::createDeviceBuffer(VkDeviceSize size, VkBufferUsageFlags usage) {
  return createBuffer(size, usage, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, false);
}

Buffer VulkanContext::createHostBuffer(VkDeviceSize size, VkBufferUsageFlags usage) {
  return createBuffer(size, usage, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT, true);
}

VkDeviceAddress VulkanContext::address(const Buffer& b) const {
  VkBufferDeviceAddressInfo info{};
  info.sType = VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO;
  info.buffer = b.buffer;
  return vkGetBufferDeviceAddress(device_, &info);
}

void VulkanContext::destroyBuffer(Buffer& b) {
  if (b.mapped) vkUnmapMemory(device_, b.memory);
  if (b.buffer) vkDestroyBuffer(device_, b.buffer, nullptr);
  if (b.memory) vkFreeMemory(device_, b.memory, nullptr);
  b = Buffer{};
}

void VulkanContext::submitOnce(const std::function<void(VkCommandBuffer)>& record) {
  VkCommandBufferAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  ai.commandPool = pool_;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cmd;
  VK_CHECK(vkAllocateCommandBuffers(device_, &ai, &cmd));
  VkCommandBufferBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(cmd, &bi));
  // Everything submitted earlier on this queue finishes writing before these commands start, and
  // later submissions (and host reads after the fence) see what these commands wrote.
  allToAll(cmd);
  record(cmd);
  allToAllAndHost(cmd);
  VK_CHECK(vkEndCommandBuffer(cmd));
  submit(cmd, once_fence_);
  VK_CHECK(vkWaitForFences(device_, 1, &once_fence_, VK_TRUE, UINT64_MAX));
  vkFreeCommandBuffers(device_, pool_, 1, &cmd);
}

void VulkanContext::submit(VkCommandBuffer cmd, VkFence fence) const {
  VK_CHECK(vkResetFences(device_, 1, &fence));
  VkCommandBufferSubmitInfo cbi{};
  cbi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO;
  cbi.commandBuffer = cmd;
  VkSubmitInfo2 si{};
  si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO_2;
  si.commandBufferInfoCount = 1;
  si.pCommandBufferInfos = &cbi;
  VK_CHECK(vkQueueSubmit2(queue_, 1, &si, fence));
}

void VulkanContext::waitIdle() { VK_CHECK(vkQueueWaitIdle(queue_)); }

void VulkanContext::download(const Buffer& src, void* data, VkDeviceSize size, VkDeviceSize offset) {
  if (size == 0) return;
  Buffer staging = createHostBuffer(size, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  submitOnce([&](VkCommandBuffer cmd) {
    VkBufferCopy region{offset, 0, size};
    vkCmdCopyBuffer(cmd, src.buffer, staging.buffer, 1, &region);
  });
  std::memcpy(data, staging.mapped, size_t(size));
  destroyBuffer(staging);
}

std::vector<VkDescriptorSet> allocateDescriptorSets(VkDevice dev, VkDescriptorPool pool, VkDescriptorSetLayout layout,
                                                    uint32_t count) {
  std::vector<VkDescriptorSetLayout> layouts(count, layout);
  std::vector<VkDescriptorSet> sets(count, VK_NULL_HANDLE);
  VkDescriptorSetAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  ai.descriptorPool = pool;
  ai.descriptorSetCount = count;
  ai.pSetLayouts = layouts.data();
  if (count) VK_CHECK(vkAllocateDescriptorSets(dev, &ai, sets.data()));
  return sets;
}

} // namespace tender::gpu
