#version 460
// The device's exactSqrt and exactDiv over many inputs (gpu::runDeviceMath): each element holds
// the bits of a and b and receives those of exactSqrt(a) and exactDiv(a, b), or with p.op 1 those
// of the plain a * b and a + b (how the device's arithmetic treats denormals).
layout(local_size_x = 64) in;
#include "exact_math.glsl"
layout(std430, set = 0, binding = 0) buffer Cases { uvec4 cases[]; };
layout(push_constant) uniform PushBlock {
  uint count;
  uint op;
}
p;

void main() {
  uint i = gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 64u + gl_GlobalInvocationID.x;
  if (i >= p.count) return;
  uvec4 c = cases[i];
  float a = uintBitsToFloat(c.x), b = uintBitsToFloat(c.y);
  if (p.op == 1u)
    cases[i] = uvec4(c.xy, floatBitsToUint(a * b), floatBitsToUint(a + b));
  else
    cases[i] = uvec4(c.xy, floatBitsToUint(exactSqrt(a)), floatBitsToUint(exactDiv(a, b)));
}
