#include "gpu/sim_pipeline.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>
#include <string_view>
#include <system_error>
#include <thread>

#include "core/denormal_mode.h"
#include "gpu/barriers.h"
#include "gpu/shaders.h"
#include "shaderio.h"

namespace tender::gpu {

namespace {
bool envOn(const char* name) {
  const char* v = std::getenv(name);
  return v && *v && std::string_view(v) != "0";
}
} // namespace

MathSwitches MathSwitches::fromEnvironment() {
  MathSwitches m;
  m.inexact = envOn("TENDER_EMULATE_INEXACT_MATH");
  m.corrected = !envOn("TENDER_UNCORRECTED_MATH");
  return m;
}

VkPipeline createSimPipeline(VulkanContext& ctx, std::string_view key, VkPipelineLayout layout, const FloatRules& rules,
                             MathSwitches math, std::optional<uint32_t> spec0, VkShaderModule& module) {
  const std::string name(key);
  std::span<const uint32_t> embedded = simShader(key);
  if (embedded.empty()) vkCheckFailed(VK_ERROR_INITIALIZATION_FAILED, name.c_str(), __FILE__, __LINE__);
  const std::vector<uint32_t> code = applyFloatRules(embedded, rules);
  VkShaderModuleCreateInfo mi{};
  mi.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  mi.codeSize = code.size() * sizeof(uint32_t);
  mi.pCode = code.data();
  VK_CHECK(vkCreateShaderModule(ctx.device(), &mi, nullptr, &module));
  // exact_math.h flushes denormals as the rest of the arithmetic does (FloatRules), on every device
  const uint32_t values[5] = {spec0.value_or(0u), math.inexact ? VK_TRUE : VK_FALSE,
                              math.corrected ? VK_TRUE : VK_FALSE, VK_TRUE, fusedCapacity(ctx)};
  const VkSpecializationMapEntry entries[5] = {{0, 0, 4},
                                               {SIM_SPEC_INEXACT_MATH, 4, 4},
                                               {SIM_SPEC_CORRECT_MATH, 8, 4},
                                               {SIM_SPEC_FLUSH_DENORMALS, 12, 4},
                                               {SIM_SPEC_FUSED_CAPACITY, 16, 4}};
  // Constant 0 only where the pass has one; the math switches and the fused tick's capacity
  // everywhere (a shader without them ignores them)
  VkSpecializationInfo spec{spec0 ? 5u : 4u, spec0 ? entries : entries + 1, sizeof(values), values};
  VkComputePipelineCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
  ci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  ci.stage.module = module;
  ci.stage.pName = "main";
  ci.stage.pSpecializationInfo = &spec;
  ci.layout = layout;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkResult r = vkCreateComputePipelines(ctx.device(), VK_NULL_HANDLE, 1, &ci, nullptr, &pipeline);
  if (r != VK_SUCCESS) {
    vkDestroyShaderModule(ctx.device(), module, nullptr);
    module = VK_NULL_HANDLE;
    vkCheckFailed(r, ("vkCreateComputePipelines " + name).c_str(), __FILE__, __LINE__);
  }
  return pipeline;
}

namespace {

/// local_size_x of a compute shader's SPIR-V: its OpExecutionMode LocalSize, or the constant
/// its OpExecutionModeId LocalSizeId names; 0 when that is a specialization constant.
uint32_t localSizeX(std::span<const uint32_t> code) {
  constexpr uint32_t kOpExecutionMode = 16, kOpExecutionModeId = 331, kOpConstant = 43;
  constexpr uint32_t kLocalSize = 17, kLocalSizeId = 38;
  uint32_t size_id = 0;
  std::vector<std::pair<uint32_t, uint32_t>> constants; // result id, value
  for (size_t w = 5; w < code.size();) {
    const uint32_t count = code[w] >> 16, op = code[w] & 0xFFFFu;
    if (count == 0 || w + count > code.size()) break;
    if (op == kOpExecutionMode && count >= 4 && code[w + 2] == kLocalSize) return code[w + 3];
    if (op == kOpExecutionModeId && count >= 4 && code[w + 2] == kLocalSizeId) size_id = code[w + 3];
    if (op == kOpConstant && count == 4) constants.emplace_back(code[w + 2], code[w + 3]);
    w += count;
  }
  for (auto [id, value] : constants)
    if (id == size_id) return value;
  return 0;
}

} // namespace

namespace {

/// The workgroup of a pipeline of `key`: its local_size_x (or the specialised size) times the
/// elements an invocation takes.
uint32_t workgroupOf(std::string_view key, uint32_t per_invocation, std::optional<uint32_t> spec0, bool spec0_is_size) {
  const uint32_t local = spec0_is_size && spec0 ? *spec0 : localSizeX(simShader(key));
  if (local == 0) vkCheckFailed(VK_ERROR_INITIALIZATION_FAILED, std::string(key).c_str(), __FILE__, __LINE__);
  return local * per_invocation;
}

} // namespace

ComputePipeline makeComputePipeline(VulkanContext& ctx, std::string_view key, const SimLayout& layout,
                                    const FloatRules& rules, MathSwitches math, uint32_t push_size,
                                    uint32_t per_invocation, std::optional<uint32_t> spec0, bool spec0_is_size) {
  PipelineRequest request{nullptr, std::string(key), push_size, per_invocation, spec0, spec0_is_size};
  ComputePipeline p;
  request.out = &p;
  makeComputePipelines(ctx, layout, rules, math, std::span<PipelineRequest>(&request, 1));
  return p;
}

void makeComputePipelines(VulkanContext& ctx, const SimLayout& layout, const FloatRules& rules, MathSwitches math,
                          std::span<PipelineRequest> requests) {
  // The workgroups first: a missing shader throws before anything is compiled
  for (PipelineRequest& r : requests) {
    r.out->push_size = r.push_size;
    r.out->workgroup = workgroupOf(r.key, r.per_invocation, r.spec0, r.spec0_is_size);
  }
  // The context's name of each: everything that makes one pipeline differ from another
  std::vector<std::string> names;
  for (const PipelineRequest& r : requests)
    names.push_back(r.key + "|" + layout.kind + "|" + (r.spec0 ? std::to_string(*r.spec0) : "-") + "|" +
                    std::to_string(int(math.inexact)) + std::to_string(int(math.corrected)) +
                    std::to_string(int(rules.rounding_rte)) + std::to_string(int(rules.denormals)));
  // Drivers compile a pipeline on the calling thread (lavapipe: seconds for the large kernels), so
  // each thread takes the next request; the context makes each name once.
  std::vector<std::exception_ptr> errors(requests.size());
  std::atomic<size_t> next{0};
  auto work = [&] {
    for (size_t k; (k = next.fetch_add(1)) < requests.size();) {
      try {
        const PipelineRequest& r = requests[k];
        r.out->pipeline = ctx.sharedPipeline(names[k], [&](VkShaderModule& module) {
          return createSimPipeline(ctx, r.key, layout.layout, rules, math, r.spec0, module);
        });
      } catch (...) {
        errors[k] = std::current_exception();
      }
    }
  };
  const size_t threads = std::min<size_t>(requests.size(), std::max(1u, std::thread::hardware_concurrency()));
  std::vector<std::thread> helpers;
  try {
    for (size_t t = 1; t < threads; ++t) helpers.emplace_back(work);
  } catch (const std::system_error&) {
    // no more threads: the calling thread takes what is left
  }
  work();
  for (std::thread& t : helpers) t.join();
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
}

namespace {

/// Every kernel of the registry (SIM_KERNELS, sim_passes.h): its shader, push constants, elements per
/// invocation, and whether a fleet runs it batched.
struct PipelineSpec {
  ComputePipeline SimPipelines::*member;
  const char* key;
  uint32_t push_size, per_invocation;
  bool batched;
};
constexpr uint32_t kSIM = sizeof(shaderio::SimPush), kSCAN = sizeof(shaderio::ScanPush), kNONE = 0;
constexpr PipelineSpec kPasses[] = {
#define SIM_KERNEL_SPEC(name, push, per_invocation, batched)                                                           \
  {&SimPipelines::name, #name ".comp", k##push, per_invocation, batched != 0},
    SIM_KERNELS(SIM_KERNEL_SPEC)
#undef SIM_KERNEL_SPEC
};

bool isContactKey(std::string_view key) { return key.starts_with("contact_"); }

} // namespace

uint32_t fusedCapacity(uint32_t shared_memory) {
  return std::min(shared_memory / uint32_t(sizeof(float) * 4), uint32_t(SIM_FUSED_MAX_PARTICLES));
}

uint32_t fusedCapacity(const VulkanContext& ctx) {
  return fusedCapacity(ctx.properties().limits.maxComputeSharedMemorySize);
}

uint32_t limitWorkgroup(const VulkanContext& ctx) {
  const VkPhysicalDeviceLimits& limits = ctx.properties().limits;
  if (ctx.properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU) return SIM_WG_LIMIT;
  return std::min(
      {uint32_t(SIM_WG_LIMIT_GPU), limits.maxComputeWorkGroupInvocations, limits.maxComputeWorkGroupSize[0]});
}

std::vector<PipelineRequest> passPipelineRequests(const VulkanContext& ctx, SimPipelines& pipes, bool batched,
                                                  bool contact) {
  using namespace shaderio;
  std::vector<PipelineRequest> requests;
  for (const PipelineSpec& spec : kPasses) {
    if ((batched && !spec.batched) || (isContactKey(spec.key) && !contact)) continue;
    const std::string key = batched ? std::string(spec.key) + ".batch" : std::string(spec.key);
    // The stretch limit's workgroup is the device's (specialization constant 0)
    const std::optional<uint32_t> size =
        spec.member == &SimPipelines::limit ? std::optional<uint32_t>(limitWorkgroup(ctx)) : std::nullopt;
    requests.push_back({&(pipes.*spec.member), key, batched ? uint32_t(sizeof(BatchPassPush)) : spec.push_size,
                        spec.per_invocation, size, size.has_value()});
  }
  return requests;
}

SimPipelines makePassPipelines(VulkanContext& ctx, const SimLayout& layout, const FloatRules& rules, MathSwitches math,
                               bool batched) {
  SimPipelines pipes;
  std::vector<PipelineRequest> requests = passPipelineRequests(ctx, pipes, batched);
  makeComputePipelines(ctx, layout, rules, math, requests);
  return pipes;
}

void addContactPipelines(VulkanContext& ctx, const SimLayout& layout, const FloatRules& rules, MathSwitches math,
                         SimPipelines& pipes, bool batched) {
  std::vector<PipelineRequest> requests;
  for (PipelineRequest& r : passPipelineRequests(ctx, pipes, batched, true))
    if (isContactKey(r.key) && !r.out->pipeline) requests.push_back(std::move(r));
  makeComputePipelines(ctx, layout, rules, math, requests);
}

namespace {

/// runDeviceMath under `rules`
void runMath(VulkanContext& ctx, std::vector<MathCase>& cases, MathSwitches math, MathOp op, const FloatRules& rules) {
  static_assert(sizeof(MathCase) == 16);
  if (cases.empty()) return;
  VkDevice dev = ctx.device();
  VkDescriptorSetLayoutBinding binding{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
  VkDescriptorSetLayoutCreateInfo sli{};
  sli.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  sli.bindingCount = 1;
  sli.pBindings = &binding;
  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, 8};
  VkPipelineLayoutCreateInfo pli{};
  pli.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  pli.setLayoutCount = 1;
  pli.pushConstantRangeCount = 1;
  pli.pPushConstantRanges = &range;
  VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1};
  VkDescriptorPoolCreateInfo dpi{};
  dpi.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  dpi.maxSets = 1;
  dpi.poolSizeCount = 1;
  dpi.pPoolSizes = &size;
  // Everything below is released on every path out (a Vulkan error throws)
  struct Objects {
    VkDevice dev;
    VulkanContext& ctx;
    VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkDescriptorPool pool = VK_NULL_HANDLE;
    VkShaderModule module = VK_NULL_HANDLE;
    VkPipeline pipeline = VK_NULL_HANDLE;
    Buffer buffer;
    ~Objects() {
      vkDestroyPipeline(dev, pipeline, nullptr);
      vkDestroyShaderModule(dev, module, nullptr);
      vkDestroyDescriptorPool(dev, pool, nullptr);
      vkDestroyPipelineLayout(dev, layout, nullptr);
      vkDestroyDescriptorSetLayout(dev, set_layout, nullptr);
      ctx.destroyBuffer(buffer);
    }
  } o{dev, ctx, VK_NULL_HANDLE, VK_NULL_HANDLE, VK_NULL_HANDLE, VK_NULL_HANDLE, VK_NULL_HANDLE, {}};
  VK_CHECK(vkCreateDescriptorSetLayout(dev, &sli, nullptr, &o.set_layout));
  pli.pSetLayouts = &o.set_layout;
  VK_CHECK(vkCreatePipelineLayout(dev, &pli, nullptr, &o.layout));
  VK_CHECK(vkCreateDescriptorPool(dev, &dpi, nullptr, &o.pool));
  o.pipeline = createSimPipeline(ctx, "math_check.comp", o.layout, rules, math, {}, o.module);

  // At most 2^16 - 1 workgroups of 64 per row; the rest of a batch spills into Y
  const uint64_t per_batch = std::min<uint64_t>(cases.size(), 1u << 22);
  o.buffer = ctx.createHostBuffer(per_batch * sizeof(MathCase), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  VkDescriptorSet set = allocateDescriptorSets(dev, o.pool, o.set_layout, 1)[0];
  VkDescriptorBufferInfo bi{o.buffer.buffer, 0, VK_WHOLE_SIZE};
  VkWriteDescriptorSet w{};
  w.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
  w.dstSet = set;
  w.descriptorCount = 1;
  w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  w.pBufferInfo = &bi;
  vkUpdateDescriptorSets(dev, 1, &w, 0, nullptr);
  for (size_t first = 0; first < cases.size(); first += per_batch) {
    const uint32_t count = uint32_t(std::min<uint64_t>(per_batch, cases.size() - first));
    std::memcpy(o.buffer.mapped, cases.data() + first, count * sizeof(MathCase));
    ctx.submitOnce([&](VkCommandBuffer cmd) {
      vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, o.pipeline);
      vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, o.layout, 0, 1, &set, 0, nullptr);
      const uint32_t push[2] = {count, uint32_t(op)};
      vkCmdPushConstants(cmd, o.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, push);
      const glm::uvec2 grid = shaderio::groupGrid((count + 63u) / 64u);
      vkCmdDispatch(cmd, grid.x, grid.y, 1);
      allToAllAndHost(cmd);
    });
    std::memcpy(cases.data() + first, o.buffer.mapped, count * sizeof(MathCase));
  }
}

/// True when the device's plain products and sums, with no flush of the shader's own, treat
/// denormals as the host does with FTZ and DAZ set: in 64 workgroups, so that every thread of a CPU
/// device's pool runs some, products that fall below the smallest normal (FTZ: zero), sums of a
/// normal and a denormal that fall below it (DAZ: the normal), and denormals times 2^23 (DAZ: zero).
bool flushesAsTheHost(VulkanContext& ctx, bool rounding_rte) {
  std::vector<MathCase> cases(64 * 64);
  for (uint32_t k = 0; k < cases.size(); ++k) {
    const uint32_t low = k & 0xFFu;
    if (k % 3 == 0) cases[k] = {0x1E3CE508u + low, 0x1E3CE508u - low, 0, 0}; // about 1e-20 squared
    if (k % 3 == 1) cases[k] = {0x00800000u + low, 0x80400000u | k, 0, 0};   // the smallest normals, less denormals
    if (k % 3 == 2) cases[k] = {0x00400000u | k, 0x4B000000u, 0, 0};         // denormals times 2^23
  }
  runMath(ctx, cases, {}, MathOp::MulAdd, {rounding_rte, Denormals::FlushByHost});
  const DenormalMode host(true);
  for (const MathCase& c : cases) {
    volatile float a = std::bit_cast<float>(c.a), b = std::bit_cast<float>(c.b);
    volatile float product = a * b, sum = a + b;
    if (c.sqrt_a != std::bit_cast<uint32_t>(float(product)) || c.a_over_b != std::bit_cast<uint32_t>(float(sum)))
      return false;
  }
  return true;
}

} // namespace

void runDeviceMath(VulkanContext& ctx, std::vector<MathCase>& cases, MathSwitches math, MathOp op) {
  runMath(ctx, cases, math, op, simFloatRules(ctx));
}

FloatRules simFloatRules(VulkanContext& ctx) {
  return ctx.floatRules([&] {
    FloatRules rules = floatRulesFor(ctx.floatControls());
    const bool cpu_device = ctx.properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    if (rules.denormals == Denormals::FlushInShader && cpu_device && flushesAsTheHost(ctx, rules.rounding_rte))
      rules.denormals = Denormals::FlushByHost;
    return rules;
  });
}

Arithmetic arithmeticOf(const FloatRules& rules, MathSwitches math) {
  Arithmetic a;
  a.rounding = rules.rounding_rte ? "nearest even" : "device default";
  a.denormals = denormalsName(rules.denormals);
  a.inexact_math_emulated = math.inexact;
  a.corrected = math.corrected;
  return a;
}

} // namespace tender::gpu
