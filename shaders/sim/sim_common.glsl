// Resources and helpers of every simulation pass: one descriptor set, bindings from sim_config.h.
#ifndef SIM_COMMON_GLSL
#define SIM_COMMON_GLSL
#include "xpbd.h"

// Every pass defines its workgroup size before including this file.
#ifndef SIM_LOCAL_SIZE
#error "define SIM_LOCAL_SIZE before including sim_common.glsl"
#endif
layout(local_size_x = SIM_LOCAL_SIZE) in;

layout(std140, set = 0, binding = SIM_BIND_UNIFORMS) uniform UniformsBlock { SimUniforms u; };
layout(std430, set = 0, binding = SIM_BIND_POS) buffer PosBuffer { vec4 pos[]; };
layout(std430, set = 0, binding = SIM_BIND_PREV) buffer PrevBuffer { vec4 prev[]; };
layout(std430, set = 0, binding = SIM_BIND_REST) readonly buffer RestBuffer { vec4 rest_pos[]; };
layout(std430, set = 0, binding = SIM_BIND_UV) readonly buffer UvBuffer { vec2 uv[]; };
layout(std430, set = 0, binding = SIM_BIND_NORMAL) buffer NormalBuffer { vec4 normal[]; };
layout(std430, set = 0, binding = SIM_BIND_CONSTRAINTS) buffer ConstraintBuffer { Constraint constraints[]; };
layout(std430, set = 0, binding = SIM_BIND_COLOR_RANGES) buffer ColorRangeBuffer { uvec2 color_range[]; };
layout(std430, set = 0, binding = SIM_BIND_ADJ_OFFSETS) readonly buffer AdjOffsetBuffer { uint adj_offsets[]; };
layout(std430, set = 0, binding = SIM_BIND_ADJ_LIST) readonly buffer AdjListBuffer { uint adj_list[]; };
layout(std430, set = 0, binding = SIM_BIND_CELL_COUNT) buffer CellCountBuffer { uint cell_count[]; };
layout(std430, set = 0, binding = SIM_BIND_CELL_START) buffer CellStartBuffer { uint cell_start[]; };
layout(std430, set = 0, binding = SIM_BIND_CELL_PARTICLES) buffer CellParticleBuffer { uint cell_particles[]; };
layout(std430, set = 0, binding = SIM_BIND_PARTICLE_CELL) buffer ParticleCellBuffer { uint particle_cell[]; };
layout(std430, set = 0, binding = SIM_BIND_DELTA) buffer DeltaBuffer { vec4 delta[]; };
layout(std430, set = 0, binding = SIM_BIND_TORN) buffer TornBuffer { uint torn[]; };
layout(std430, set = 0, binding = SIM_BIND_TRIANGLES) buffer TriangleBuffer { uvec4 triangles[]; };
layout(std430, set = 0, binding = SIM_BIND_TRI_EDGES) readonly buffer TriEdgeBuffer { uvec2 tri_edges[]; };
layout(std430, set = 0, binding = SIM_BIND_COUNTERS) buffer CounterBuffer { Counters counters; };
layout(std430, set = 0, binding = SIM_BIND_SCRATCH) buffer ScratchBuffer { uint scratch[]; };
layout(std430, set = 0, binding = SIM_BIND_PICK) buffer PickBuffer {
  uint pick_index;
  float pick_t;
  uint pick_d2;
  uint pick_pad;
};
layout(std430, set = 0, binding = SIM_BIND_RESET_FROM) buffer ResetFromBuffer { vec4 reset_from[]; };
layout(std430, set = 0, binding = SIM_BIND_CELL_SCATTER) buffer CellScatterBuffer { uint cell_scatter[]; };
layout(std430, set = 0, binding = SIM_BIND_COMPACT_TMP) buffer CompactTmpBuffer { uvec4 compact_tmp[]; };
// Positions in bucket order (a copy of pos[cell_particles[k]]), so collide reads buckets contiguously
layout(std430, set = 0, binding = SIM_BIND_CELL_POS) buffer CellPosBuffer { vec4 cell_pos[]; };

// Linear index of this invocation; grids wider than SIM_MAX_GROUPS_X spill into Y.
uint threadIndex() {
  return (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * SIM_LOCAL_SIZE + gl_LocalInvocationID.x;
}

// Linear index of this workgroup.
uint groupIndex() { return gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x; }

// Colour of constraint slot k: the last colour whose (fixed) first slot is <= k.
uint colorOf(uint k) {
  uint lo = 0u, hi = u.color_count; // answer in [lo, hi)
  while (hi - lo > 1u) {
    uint mid = (lo + hi) / 2u;
    if (color_range[mid].x <= k)
      lo = mid;
    else
      hi = mid;
  }
  return lo;
}

// Slots the tear compaction covers: constraints, triangles, and one end slot for the totals.
uint compactSlots() { return u.constraint_count + u.triangle_count + 1u; }

#endif
