#version 460
// Spatial hash, step 3: each particle takes a slot of its bucket. The count is used as a
// down-counter, so every count is back at zero for the next rebuild.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#include "sim_common.glsl"
layout(push_constant) uniform PushBlock { SimPush p; };

void main() {
  uint i = threadIndex();
  if (i >= p.count) return;
  uint h = particle_cell[i];
  uint slot = atomicAdd(cell_count[h], 0xFFFFFFFFu) - 1u;
  cell_scatter[cell_start[h] + slot] = i;
}
