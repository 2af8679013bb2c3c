#version 460
// One frame of the animated reset: positions blend from where they were to their start.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "sim_common.glsl"

void main() {
  uint i = threadIndex();
  if (i >= p.count) return;
  float w = inverseMass(rest_pos[i], false, u.flags);
  vec4 q = vec4(blend3(vec3(reset_from[i]), vec3(rest_pos[i]), u.reset_alpha), w);
  pos[i] = q;
  prev[i] = q;
}
