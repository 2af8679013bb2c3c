#version 460
// Contact (contact.glsl): each live triangle's and edge's box entered in the buckets of its cells
// (their starts scanned from the counts).
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "contact.glsl"
#include "sim_common.glsl"

void main() {
  uint k = threadIndex();
  if (k < p.count) contactInsert(k, true);
}
