#version 460
// Tear compaction, step 3 (indirect): survivors move to their scanned place (stable, each colour
// range keeps its first slot); the colour counts and the triangle count shrink.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_TEAR
#include "sim_common.glsl"
#include "sim_elements.glsl"

void main() {
  uint k = threadIndex();
  if (k < compactSlots()) tearCompact(k);
}
