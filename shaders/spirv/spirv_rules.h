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

/// How the simulation's shaders treat denormals on a device.
enum class Denormals {
  Preserve,      ///< requested (DenormPreserve): as the CPU reference does by default
  FlushToZero,   ///< requested (DenormFlushToZero): the CPU reference must flush too
  DeviceDefault, ///< the device can be asked for neither: Vulkan lets it flush or keep them
};

/// The execution modes the simulation's shaders request on a device with `fc`: round to nearest
/// even when it can be asked for, and denormals kept, else flushed, else left to the device.
struct FloatRules {
  bool rounding_rte = false;
  Denormals denormals = Denormals::DeviceDefault;
};
FloatRules floatRulesFor(const FloatControls& fc);

/// "preserve", "flush to zero" or "device default".
const char* denormalsName(Denormals d);

/// True for the SPIR-V opcodes of float arithmetic (OpFAdd, OpFMul, OpDot, ...) that a device may
/// fuse or reassociate unless their result is decorated NoContraction.
bool isFloatArithmetic(uint32_t opcode);

/// `code` with NoContraction on the result of every float arithmetic instruction and the
/// execution modes (and capabilities) of `rules` on every entry point. `code` must be a valid
/// module of SPIR-V 1.4 or later (float controls are core there).
std::vector<uint32_t> applyFloatRules(std::span<const uint32_t> code, const FloatRules& rules);

} // namespace tender::gpu
