#version 460
// Gathers repulsion from non-adjacent neighbours in the surrounding cells (Jacobi: writes delta
// only). Cells, and particles within a cell, are visited in the CPU reference's order.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_COLLIDE
#include "sim_common.glsl"
#include "sim_elements.glsl"
layout(push_constant) uniform PushBlock { SimPush p; };

void main() {
  uint i = threadIndex();
  if (i >= p.count) return;
  bool fits;
  delta[i] = vec4(gatherRepulsion(i, vec3(pos[i]), u.collision_radius, SIM_NONE, fits), 0.0f);
}
