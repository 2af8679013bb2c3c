#pragma once
/// Compute pipelines of the simulation's shaders: their SPIR-V under the device's float rules
/// (spirv_rules.h) and the switches of exact_math.h as specialization constants.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/solver.h"
#include "gpu/context.h"
#include "sim_passes.h"
#include "spirv_rules.h"

namespace tender::gpu {

/// The switches of exact_math.h. From the environment: TENDER_EMULATE_INEXACT_MATH=1 emulates an
/// inexact device's sqrt and divide (off by -3..+3 ULP), TENDER_UNCORRECTED_MATH=1 leaves them
/// uncorrected (to show what the correction is for: parity with the CPU is then lost).
struct MathSwitches {
  bool inexact = false;
  bool corrected = true;
  static MathSwitches fromEnvironment();
};

/// How the simulation's shaders compute under these rules and switches (Solver::arithmetic).
Arithmetic arithmeticOf(const FloatRules& rules, MathSwitches math);

/// A compute pipeline of shaders/sim/<key>.glsl on `layout`; `spec0` sets specialization constant 0
/// where the shader has one. The module goes to `module` (destroy it with the pipeline). Throws
/// VulkanError when the shader is missing or Vulkan fails.
VkPipeline createSimPipeline(VulkanContext& ctx, std::string_view key, VkPipelineLayout layout, const FloatRules& rules,
                             MathSwitches math, std::optional<uint32_t> spec0, VkShaderModule& module);

/// A compute pipeline and what dispatching it needs.
struct ComputePipeline {
  VkPipeline pipeline = VK_NULL_HANDLE;
  uint32_t push_size = 0; ///< bytes of the shader's push-constant block (0: none)
  uint32_t workgroup = 0; ///< elements one workgroup covers: local_size_x (from the SPIR-V) x elements per invocation
};

/// Every pipeline of the simulation (one file per shader in shaders/sim/): a member per kernel of
/// the registry (SIM_KERNELS, sim_passes.h), the fused tick and the picks.
struct SimPipelines {
#define SIM_KERNEL_MEMBER(name, push, per_invocation, batched) ComputePipeline name;
  SIM_KERNELS(SIM_KERNEL_MEMBER)
#undef SIM_KERNEL_MEMBER
  ComputePipeline tick_fused;         ///< the fused tick of sheets up to fusedCapacity
  ComputePipeline tick_fused_contact; ///< the fused tick with contact
  std::array<ComputePipeline, 3> pick;
};

/// A pipeline layout of the simulation's kernels and its kind. Layouts of one kind are defined alike
/// (the same set layouts and push-constant range: compatible, in Vulkan's words), so a pipeline made
/// on one serves them all: the context keeps one pipeline per kernel, kind, specialization and math
/// for every solver and fleet on it (VulkanContext::sharedPipeline).
struct SimLayout {
  VkPipelineLayout layout = VK_NULL_HANDLE;
  const char* kind = ""; ///< "sheet" (a sheet's set, SimPush), "solver" (a sheet's set, PickPush), "batch"
};

/// A ComputePipeline of shaders/sim/<key>.glsl (see createSimPipeline) whose push constants take
/// `push_size` bytes and whose invocations take `per_invocation` elements each; the workgroup size
/// comes from the SPIR-V, or is `spec0` for a shader whose size is specialization constant 0
/// (`spec0_is_size`). The context keeps it (SimLayout).
ComputePipeline makeComputePipeline(VulkanContext& ctx, std::string_view key, const SimLayout& layout,
                                    const FloatRules& rules, MathSwitches math, uint32_t push_size,
                                    uint32_t per_invocation, std::optional<uint32_t> spec0, bool spec0_is_size);

/// One pipeline of makeComputePipelines: what makeComputePipeline takes, and where it goes.
struct PipelineRequest {
  ComputePipeline* out;
  std::string key;
  uint32_t push_size, per_invocation;
  std::optional<uint32_t> spec0;
  bool spec0_is_size;
};

/// The pipelines of `requests`: those the context has not made yet compiled side by side on every
/// core (drivers compile on the calling thread). Each goes to its request's `out`; when any fails,
/// the first error is thrown after every other has been made.
void makeComputePipelines(VulkanContext& ctx, const SimLayout& layout, const FloatRules& rules, MathSwitches math,
                          std::span<PipelineRequest> requests);

/// Particles the fused tick holds in `shared_memory` bytes of shared memory (a vec4 each), at most
/// SIM_FUSED_MAX_PARTICLES: the largest sheet it takes (specialization constant
/// SIM_SPEC_FUSED_CAPACITY of every pipeline).
uint32_t fusedCapacity(uint32_t shared_memory);
/// ... on this device (its maxComputeSharedMemorySize).
uint32_t fusedCapacity(const VulkanContext& ctx);

/// Invocations of the stretch limit's workgroup (limit.comp) on this device: SIM_WG_LIMIT on a CPU
/// device, SIM_WG_LIMIT_GPU (or the device's most) on a GPU.
uint32_t limitWorkgroup(const VulkanContext& ctx);

/// The passes of the per-colour path (every SimPipelines member but the fused ticks and pick) on
/// `layout`: a sheet's own, or a fleet's (`batched`: the SIM_BATCH_PASS builds, "<key>.batch",
/// whose push constants are BatchPassPush; no normals pass). The contact's kernels (contact_*)
/// wait for a sheet's first tick with contact (passPipelineRequests) or a fleet's (addContactPipelines).
SimPipelines makePassPipelines(VulkanContext& ctx, const SimLayout& layout, const FloatRules& rules, MathSwitches math,
                               bool batched);

/// What makePassPipelines makes, as requests into `pipes` (to make with others); with `contact`,
/// the contact's kernels too.
std::vector<PipelineRequest> passPipelineRequests(const VulkanContext& ctx, SimPipelines& pipes, bool batched,
                                                  bool contact = false);

/// Adds the contact's kernels (contact_*) to a fleet's `pipes`, passes on `layout` as
/// makePassPipelines makes them (`batched`: run once for the whole batch): made when its passes
/// first run a sheet with contact, so that a fleet without it does not compile them. Nothing when
/// they are made.
void addContactPipelines(VulkanContext& ctx, const SimLayout& layout, const FloatRules& rules, MathSwitches math,
                         SimPipelines& pipes, bool batched = false);

/// One input of the device math check and its results (bits of floats).
struct MathCase {
  uint32_t a = 0, b = 0;
  uint32_t sqrt_a = 0, a_over_b = 0; ///< exactSqrt(a) and exactDiv(a, b) as the device computed them
};

/// What the device math check computes: exactSqrt(a) and exactDiv(a, b), or the plain products
/// and sums a * b and a + b (in the sqrt_a and a_over_b fields), which show how the device's
/// arithmetic treats denormals.
enum class MathOp : uint32_t { ExactSqrtDiv = 0, MulAdd = 1 };

/// Runs the check of every case on the device (the shader math_check.comp), under simFloatRules.
void runDeviceMath(VulkanContext& ctx, std::vector<MathCase>& cases, MathSwitches math,
                   MathOp op = MathOp::ExactSqrtDiv);

/// The float rules of the simulation's shaders on the device of `ctx`, decided once a context:
/// floatRulesFor its float controls, where a CPU device that cannot be asked to flush denormals
/// flushes them with the host's FTZ and DAZ (Denormals::FlushByHost) when a probe shows that its
/// threads have them (VulkanContext::create starts them so). There the shaders carry no flush of their
/// own, which on lavapipe costs a quarter of a kernel's run and of its compile.
FloatRules simFloatRules(VulkanContext& ctx);

} // namespace tender::gpu
