#version 460
// Adds each block's scanned offset (scratch[sums + block]) to the elements of that block.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_TEAR
#define SIM_PUSH_TYPE ScanPush
#include "sim_common.glsl"

void main() {
  uint i = threadIndex();
  if (i >= p.count) return;
  uint add = scratch[p.sums + i / SIM_SCAN_BLOCK];
  if (p.mode == SIM_SCAN_HASH)
    cell_start[i] += add;
  else
    scratch[p.offset + i] += add;
}
