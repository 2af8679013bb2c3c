#version 460
// The air on each particle (SIM_FLAG_AIR: airOnParticle) into delta, which integration reads next.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "sim_common.glsl"
#include "sim_elements.glsl"

void main() {
  uint i = threadIndex();
  if (i >= p.count) return;
  delta[i] = vec4(airOnParticle(i), 0.0f);
}
