#version 460
// Smooth grid normals from central differences (clamped at the edges).
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "sim_common.glsl"

void main() {
  uint idx = threadIndex();
  if (idx >= p.count) return;
  uint w = u.cols, h = u.rows;
  uint i = idx % w, j = idx / w;
  uint l = j * w + (i > 0u ? i - 1u : i), r = j * w + (i + 1u < w ? i + 1u : i);
  uint up = (j > 0u ? j - 1u : j) * w + i, dn = (j + 1u < h ? j + 1u : j) * w + i;
  normal[idx] = vec4(gridNormal(vec3(pos[l]), vec3(pos[r]), vec3(pos[up]), vec3(pos[dn])), 0.0f);
}
