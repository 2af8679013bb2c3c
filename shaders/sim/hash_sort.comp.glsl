#version 460
// Spatial hash, step 4: orders each bucket by particle index. A particle's place in its bucket
// is the number of bucket entries with a smaller index (ranks are unique, so no races). The
// position goes along, so the collision gather reads buckets as one contiguous array.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#include "sim_common.glsl"
layout(push_constant) uniform PushBlock { SimPush p; };

void main() {
  uint i = threadIndex();
  if (i >= p.count) return;
  uint h = particle_cell[i];
  uint first = cell_start[h], end = cell_start[h + 1u];
  uint rank = 0u;
  for (uint k = first; k < end; ++k) rank += cell_scatter[k] < i ? 1u : 0u;
  cell_particles[first + rank] = i;
  cell_pos[first + rank] = pos[i];
}
