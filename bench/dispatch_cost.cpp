// The cost of an empty dispatch and barrier on a device (see dispatch_cost.h).
#include "dispatch_cost.h"

#include <algorithm>
#include <span>
#include <string_view>

#include "gpu/barriers.h"

namespace tender::gpu {
/// SPIR-V of shaders/bench/<key>.glsl (tender_bench_shaders), or an empty span.
std::span<const uint32_t> benchShader(std::string_view key);
} // namespace tender::gpu

namespace tender::bench {

namespace {

/// The Vulkan objects of one measurement, destroyed whichever way it ends.
struct Objects {
  VkDevice device = VK_NULL_HANDLE;
  VkShaderModule module = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkQueryPool queries = VK_NULL_HANDLE;
  ~Objects() {
    if (device == VK_NULL_HANDLE) return;
    vkDestroyQueryPool(device, queries, nullptr);
    vkDestroyPipeline(device, pipeline, nullptr);
    vkDestroyPipelineLayout(device, layout, nullptr);
    vkDestroyShaderModule(device, module, nullptr);
  }
};

/// The mask of a timestamp's bits that count on the context's queue (the rest may hold anything).
uint64_t timestampMask(const gpu::VulkanContext& ctx) {
  uint32_t family_count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(ctx.physicalDevice(), &family_count, nullptr);
  std::vector<VkQueueFamilyProperties> families(family_count);
  vkGetPhysicalDeviceQueueFamilyProperties(ctx.physicalDevice(), &family_count, families.data());
  const uint32_t bits = ctx.queueFamily() < family_count ? families[ctx.queueFamily()].timestampValidBits : 64;
  return bits >= 64 ? ~uint64_t(0) : (uint64_t(1) << bits) - 1;
}

/// The empty shader's pipeline and a pool of 2 x `repetitions` timestamps.
void createObjects(Objects& o, std::span<const uint32_t> code, uint32_t repetitions) {
  VkShaderModuleCreateInfo mci{};
  mci.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  mci.codeSize = code.size_bytes();
  mci.pCode = code.data();
  VK_CHECK(vkCreateShaderModule(o.device, &mci, nullptr, &o.module));
  VkPipelineLayoutCreateInfo lci{};
  lci.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  VK_CHECK(vkCreatePipelineLayout(o.device, &lci, nullptr, &o.layout));
  VkComputePipelineCreateInfo pci{};
  pci.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
  pci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  pci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  pci.stage.module = o.module;
  pci.stage.pName = "main";
  pci.layout = o.layout;
  VK_CHECK(vkCreateComputePipelines(o.device, VK_NULL_HANDLE, 1, &pci, nullptr, &o.pipeline));
  VkQueryPoolCreateInfo qci{};
  qci.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
  qci.queryType = VK_QUERY_TYPE_TIMESTAMP;
  qci.queryCount = 2 * repetitions;
  VK_CHECK(vkCreateQueryPool(o.device, &qci, nullptr, &o.queries));
}

} // namespace

std::optional<DispatchCost> measureDispatchCost(gpu::VulkanContext& ctx, std::string& error, uint32_t chain,
                                                uint32_t repetitions) {
  if (chain == 0 || repetitions == 0) {
    error = "an empty chain";
    return std::nullopt;
  }
  if (!ctx.timestampsSupported()) {
    error = "the queue has no timestamps";
    return std::nullopt;
  }
  const std::span<const uint32_t> code = gpu::benchShader("empty.comp");
  if (code.empty()) {
    error = "the empty shader is not built in";
    return std::nullopt;
  }
  const uint64_t mask = timestampMask(ctx);
  try {
    Objects o;
    o.device = ctx.device();
    createObjects(o, code, repetitions);
    const uint32_t query_count = 2 * repetitions;
    ctx.submitOnce([&](VkCommandBuffer cmd) {
      vkCmdResetQueryPool(cmd, o.queries, 0, query_count);
      vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, o.pipeline);
      auto dispatches = [&](uint32_t count) {
        for (uint32_t k = 0; k < count; ++k) {
          vkCmdDispatch(cmd, 1, 1, 1);
          gpu::computeToCompute(cmd);
        }
      };
      dispatches(std::max(chain / 10, 1u)); // untimed: caches, clocks and the driver's first-use work
      for (uint32_t r = 0; r < repetitions; ++r) {
        vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, o.queries, 2 * r);
        dispatches(chain);
        vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, o.queries, 2 * r + 1);
      }
    });
    std::vector<uint64_t> ts(query_count);
    VK_CHECK(vkGetQueryPoolResults(o.device, o.queries, 0, query_count, ts.size() * sizeof(uint64_t), ts.data(),
                                   sizeof(uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
    DispatchCost cost;
    cost.chain = chain;
    cost.repetitions = repetitions;
    for (uint32_t r = 0; r < repetitions; ++r) {
      const uint64_t ticks = (ts[2 * r + 1] - ts[2 * r]) & mask;
      cost.samples_us.push_back(double(ticks) * ctx.timestampPeriod() * 1e-3 / double(chain));
    }
    std::vector<double> sorted = cost.samples_us;
    std::sort(sorted.begin(), sorted.end());
    const size_t mid = sorted.size() / 2;
    cost.us = sorted.size() % 2 ? sorted[mid] : 0.5 * (sorted[mid - 1] + sorted[mid]);
    cost.method = "chains of " + std::to_string(chain) +
                  " empty dispatches (1 workgroup of 64), each followed by a compute-to-compute barrier, "
                  "timestamps around each chain, median of " +
                  std::to_string(repetitions) + " on " + ctx.properties().deviceName;
    return cost;
  } catch (const gpu::VulkanError& e) {
    error = e.what();
    return std::nullopt;
  }
}

} // namespace tender::bench
