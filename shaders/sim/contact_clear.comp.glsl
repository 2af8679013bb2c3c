#version 460
// Contact (contact.glsl): each particle's start of the substep; the grid's buckets and the triangles'
// crossing flags cleared; the longest live edge.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "contact.glsl"
#include "sim_common.glsl"

void main() {
  uint k = threadIndex();
  if (k < p.count) contactClear(k);
}
