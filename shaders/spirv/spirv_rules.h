#pragma once
/// The rules of float arithmetic every simulation shader runs under, written into its SPIR-V when
/// the pipeline is made: no contraction or reassociation anywhere, and the rounding and denormal
/// handling the device can be asked for (SPIR-V float controls, core in Vulkan 1.2).
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace tender::gpu {

/// What a device's 32-bit float controls allow (VkPhysicalDeviceFloatControlsProperties).
struct FloatControls {
  bool rounding_rte = false;    ///< shaderRoundingModeRTEFloat32
  bool denorm_preserve = false; ///< shaderDenormPreserveFloat32
  bool denorm_flush = false;    ///< shaderDenormFlushToZeroFloat32
};

/// How the simulation's shaders flush denormals on a device. Every device and the CPU reference
/// treat them alike, as x86 does with FTZ and DAZ set (a result below the smallest normal is a
/// zero of its sign), since that is what every GPU can be held to: NVIDIA's can be asked neither
/// to keep nor to flush them, and its compiler flushes some operations and keeps others.
enum class Denormals {
  FlushToZero,   ///< the device flushes them, asked to (DenormFlushToZero)
  FlushInShader, ///< the device cannot be asked to: every float result is flushed by the shader's own code
  FlushByHost,   ///< a CPU device's threads flush them with the host's FTZ and DAZ (proven by gpu::simFloatRules)
  AsWritten,     ///< neither asked for nor written in (the build's pass before spirv-opt, which marks NoContraction)
};

/// The execution modes the simulation's shaders request on a device with `fc`: round to nearest
/// even when it can be asked for, and denormals flushed by the device when it can be asked to.
struct FloatRules {
  bool rounding_rte = false;
  Denormals denormals = Denormals::FlushInShader;
};
FloatRules floatRulesFor(const FloatControls& fc);

/// "flush to zero (device)" or "flush to zero (shader)".
const char* denormalsName(Denormals d);

/// True for the SPIR-V opcodes of float arithmetic (OpFAdd, OpFMul, OpDot, ...) that a device may
/// fuse or reassociate unless their result is decorated NoContraction.
bool isFloatArithmetic(uint32_t opcode);

/// `code` with NoContraction on the result of every float arithmetic instruction and the
/// execution modes (and capabilities) of `rules` on every entry point; with
/// Denormals::FlushInShader, each float arithmetic result in a function, and each float loaded
/// from a buffer, uniform or push constant, and each made from bits (OpBitcast), also passes through a flush (a
/// denormal becomes the zero of its sign: bitcast, mask, compare, select), so that no denormal ever reaches the
/// device's arithmetic and its own handling of them never shows. `code` must be a valid module of SPIR-V 1.4 or
/// later (float controls are core there).
std::vector<uint32_t> applyFloatRules(std::span<const uint32_t> code, const FloatRules& rules);

/// Where a simulation shader asks the device for a result the device may round its own way
/// (shaders/shared/exact_math.h): an OpFDiv outside deviceDiv, a GLSL.std.450 Sqrt outside
/// deviceSqrt, a call of either from anywhere but exactDiv and exactSqrt, an OpFRem or OpFMod
/// anywhere; one line each ("in <function>: OpFDiv"). (Other GLSL.std.450 instructions whose
/// result the device chooses are refused by tests/gpu/spirv_rules_test.cpp.) `code` is the module as glslc wrote it,
/// its functions named and not yet inlined. Only these operations can differ on a device whose sqrt and divide are off
/// by a few ULP (the emulated inexact device, TENDER_EMULATE_INEXACT_MATH), so with none the correction holds at every
/// call.
std::vector<std::string> inexactOperations(std::span<const uint32_t> code);

} // namespace tender::gpu
