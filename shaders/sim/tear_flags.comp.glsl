#version 460
// Tear compaction, step 1 (indirect): a keep flag per constraint slot and per triangle, and a
// copy of each element to compact from. The scan of the flags gives every survivor its place.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_TEAR
#include "sim_common.glsl"
#include "sim_elements.glsl"

void main() {
  uint k = threadIndex();
  if (k < compactSlots()) tearFlags(k);
}
