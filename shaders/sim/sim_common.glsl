// Resources and helpers of every simulation pass: one descriptor set, bindings from sim_config.h.
#ifndef SIM_COMMON_GLSL
#define SIM_COMMON_GLSL
#include "exact_math.glsl"
#include "xpbd.h"

// Every pass defines its workgroup size before including this file.
#ifndef SIM_LOCAL_SIZE
#error "define SIM_LOCAL_SIZE before including sim_common.glsl"
#endif
#ifdef SIM_LOCAL_SIZE_SPECIALIZED
// The workgroup size is specialization constant 0 (SIM_LOCAL_SIZE when not specialised)
layout(local_size_x = SIM_LOCAL_SIZE, local_size_x_id = 0) in;
#else
layout(local_size_x = SIM_LOCAL_SIZE) in;
#endif

// A shader whose invocations exchange data through buffers inside one dispatch (the fused tick)
// defines SIM_COHERENT as `coherent` before including this file.
#ifndef SIM_COHERENT
#define SIM_COHERENT
#endif

layout(std140, set = 0, binding = SIM_BIND_UNIFORMS) uniform UniformsBlock { SimUniforms u; };
layout(std430, set = 0, binding = SIM_BIND_POS) SIM_COHERENT buffer PosBuffer { vec4 pos[]; };
layout(std430, set = 0, binding = SIM_BIND_PREV) SIM_COHERENT buffer PrevBuffer { vec4 prev[]; };
layout(std430, set = 0, binding = SIM_BIND_REST) readonly buffer RestBuffer { vec4 rest_pos[]; };
layout(std430, set = 0, binding = SIM_BIND_UV) readonly buffer UvBuffer { vec2 uv[]; };
layout(std430, set = 0, binding = SIM_BIND_NORMAL) SIM_COHERENT buffer NormalBuffer { vec4 normal[]; };
layout(std430, set = 0, binding = SIM_BIND_CONSTRAINTS) SIM_COHERENT buffer ConstraintBuffer {
  Constraint constraints[];
};
layout(std430, set = 0, binding = SIM_BIND_COLOR_RANGES) SIM_COHERENT buffer ColorRangeBuffer { uvec2 color_range[]; };
layout(std430, set = 0, binding = SIM_BIND_ADJ_OFFSETS) readonly buffer AdjOffsetBuffer { uint adj_offsets[]; };
layout(std430, set = 0, binding = SIM_BIND_ADJ_LIST) readonly buffer AdjListBuffer { uint adj_list[]; };
layout(std430, set = 0, binding = SIM_BIND_ADJ_MASK) readonly buffer AdjMaskBuffer { uint adj_mask[]; };
layout(std430, set = 0, binding = SIM_BIND_CELL_COUNT) SIM_COHERENT buffer CellCountBuffer { uint cell_count[]; };
layout(std430, set = 0, binding = SIM_BIND_CELL_START) SIM_COHERENT buffer CellStartBuffer { uint cell_start[]; };
layout(std430, set = 0, binding = SIM_BIND_CELL_PARTICLES) SIM_COHERENT buffer CellParticleBuffer {
  uint cell_particles[];
};
layout(std430, set = 0, binding = SIM_BIND_PARTICLE_CELL) SIM_COHERENT buffer ParticleCellBuffer {
  uint particle_cell[];
};
layout(std430, set = 0, binding = SIM_BIND_DELTA) SIM_COHERENT buffer DeltaBuffer { vec4 delta[]; };
layout(std430, set = 0, binding = SIM_BIND_TORN) SIM_COHERENT buffer TornBuffer { uint torn[]; };
layout(std430, set = 0, binding = SIM_BIND_TRIANGLES) SIM_COHERENT buffer TriangleBuffer { uvec4 triangles[]; };
layout(std430, set = 0, binding = SIM_BIND_TRI_EDGES) readonly buffer TriEdgeBuffer { uvec2 tri_edges[]; };
layout(std430, set = 0, binding = SIM_BIND_COUNTERS) SIM_COHERENT buffer CounterBuffer { Counters counters; };
layout(std430, set = 0, binding = SIM_BIND_SCRATCH) SIM_COHERENT buffer ScratchBuffer { uint scratch[]; };
layout(std430, set = 0, binding = SIM_BIND_PICK) SIM_COHERENT buffer PickBuffer {
  uint pick_index;
  float pick_t;
  uint pick_d2;
  uint pick_pad;
  vec4 pick_pos;
};
layout(std430, set = 0, binding = SIM_BIND_RESET_FROM) SIM_COHERENT buffer ResetFromBuffer { vec4 reset_from[]; };
layout(std430, set = 0, binding = SIM_BIND_CELL_SCATTER) SIM_COHERENT buffer CellScatterBuffer { uint cell_scatter[]; };
layout(std430, set = 0, binding = SIM_BIND_COMPACT_TMP) SIM_COHERENT buffer CompactTmpBuffer { uvec4 compact_tmp[]; };
// Bucket order: xyz the bits of pos[cell_particles[k]].xyz, w the particle cell_particles[k], so
// collide reads buckets contiguously in one load per candidate
layout(std430, set = 0, binding = SIM_BIND_CELL_POS) SIM_COHERENT buffer CellPosBuffer { uvec4 cell_pos[]; };
// Candidate lists of the fused tick and the positions they were built at (SIM_CANDIDATE_* in sim_config.h)
layout(std430, set = 0, binding = SIM_BIND_CANDIDATES) SIM_COHERENT buffer CandidateBuffer { uint candidates[]; };
layout(std430, set = 0, binding = SIM_BIND_CANDIDATE_BASE) SIM_COHERENT buffer CandidateBaseBuffer {
  vec4 candidate_base[];
};
// Indirect arguments of the separate hash passes: SIM_HASH_DISPATCHES live, then as many full
layout(std430, set = 0, binding = SIM_BIND_HASH_ARGS) SIM_COHERENT buffer HashArgsBuffer { uvec4 hash_args[]; };

// Linear index of this invocation; grids wider than SIM_MAX_GROUPS_X spill into Y.
uint threadIndex() {
  return (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
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

// Collision candidate lists (SIM_CANDIDATE_* in sim_config.h, collideMode and the rest in xpbd.h) with
// the current parameters: their skin (0: none kept), search radius, mode and next state.
float candidateSkinNow() {
  return (u.flags & SIM_FLAG_CANDIDATES) != 0u ? candidateSkin(u.collision_radius, u.inv_cell) : 0.0f;
}
float candidateSearchNow() { return u.collision_radius + candidateSkinNow(); }
bool candidatesCurrentNow(uvec4 state) { return candidatesCurrent(state, candidateSkinNow(), candidateSearchNow()); }
uint collideModeOf(uvec4 state, bool travelled) {
  return collideMode(state, travelled, candidateSkinNow(), candidateSearchNow());
}
uvec4 candidatesNextStateOf(uvec4 state, uint mode, bool overflow) {
  return candidatesNextState(state, mode, overflow, candidateSearchNow());
}

// The mode of this substep in the separate passes (candidates_check has run).
uint collideModeNow() { return collideModeOf(counters.candidate_state, counters.candidate_flags.x != 0u); }

// Slots the tear compaction covers: constraints, triangles, and one end slot for the totals.
uint compactSlots() { return u.constraint_count + u.triangle_count + 1u; }

#endif
