#version 460
// Exclusive block scan of SIM_SCAN_BLOCK elements per workgroup; writes each block's total to
// scratch[sums + block]. Blocks are combined by scanning the sums and adding them back (scan_add).
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_SCAN
#define SIM_PUSH_TYPE ScanPush
#include "sim_common.glsl"

shared uint partial[SIM_WG_SCAN];

uint load(uint i) {
  if (i >= p.count) return 0u;
  // Each array read only in its own mode (a fleet's arrays are not bounds-checked)
  if (p.mode == SIM_SCAN_HASH) return cell_count[i];
  return scratch[p.offset + i];
}

void store(uint i, uint v) {
  if (i >= p.count) return;
  if (p.mode == SIM_SCAN_HASH)
    cell_start[i] = v;
  else
    scratch[p.offset + i] = v;
}

void main() {
  uint block = groupIndex();
  if (block * SIM_SCAN_BLOCK >= p.count) return; // the whole workgroup leaves together
  uint lid = gl_LocalInvocationID.x;
  uint base = block * SIM_SCAN_BLOCK + lid * SIM_SCAN_PER_THREAD;
  // Each thread scans its own elements
  uint v[SIM_SCAN_PER_THREAD];
  uint sum = 0u;
  for (uint k = 0u; k < SIM_SCAN_PER_THREAD; ++k) {
    v[k] = load(base + k);
    sum += v[k];
  }
  partial[lid] = sum;
  barrier();
  // Inclusive Hillis-Steele scan of the thread totals
  for (uint off = 1u; off < SIM_WG_SCAN; off *= 2u) {
    uint add = lid >= off ? partial[lid - off] : 0u;
    barrier();
    partial[lid] += add;
    barrier();
  }
  uint run = lid > 0u ? partial[lid - 1u] : 0u;
  for (uint k = 0u; k < SIM_SCAN_PER_THREAD; ++k) {
    store(base + k, run);
    run += v[k];
  }
  if (lid == SIM_WG_SCAN - 1u) scratch[p.sums + block] = partial[lid];
}
