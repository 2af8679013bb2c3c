#version 460
// Spatial hash, step 3: each particle takes a slot of its bucket (counts end back at zero).
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#include "sim_common.glsl"
#include "sim_elements.glsl"
layout(push_constant) uniform PushBlock { SimPush p; };

void main() {
  uint i = threadIndex();
  if (i >= p.count) return;
  hashScatter(i);
}
