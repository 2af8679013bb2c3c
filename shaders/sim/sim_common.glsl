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

// A fleet's shaders: tick_batch.comp (SIM_BATCH: the fused tick, a sheet per workgroup) and the
// per-colour passes built with SIM_BATCH_PASS (a sheet per workgroup z, BatchArgs.gate choosing the
// sheets). Every array is the sheet's slice of its buffer, reached by device address (SIM_BATCH_*
// in sim_config.h); the names below stand for those slices, so the passes' code reads the same in
// every build.
#if defined(SIM_BATCH) || defined(SIM_BATCH_PASS)
#define SIM_BATCHED
#endif

// Every pass names the type of its push constants (SimPush, ScanPush, ...) in SIM_PUSH_TYPE before
// including this file; a fleet's shaders follow them with BatchArgs.
#ifdef SIM_BATCHED
#ifndef SIM_PUSH_TYPE
#define SIM_PUSH_TYPE uvec4
#endif
layout(push_constant) uniform PushBlock {
  SIM_PUSH_TYPE p;
  BatchArgs batch;
};
#elif defined(SIM_PUSH_TYPE)
layout(push_constant) uniform PushBlock { SIM_PUSH_TYPE p; };
#endif

#ifdef SIM_BATCHED
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer BatchTableRef { uvec4 entry[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer QueueRef { uint sheet[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer UniformsRef { SimUniforms v; };
layout(buffer_reference, std430, buffer_reference_align = 16) SIM_COHERENT buffer Vec4Ref { vec4 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) SIM_COHERENT buffer Uvec4Ref { uvec4 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 8) SIM_COHERENT buffer Uvec2Ref { uvec2 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer Vec2Ref { vec2 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) SIM_COHERENT buffer UintRef { uint v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) SIM_COHERENT buffer ConstraintRef { Constraint v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) SIM_COHERENT buffer ContactRef { ContactParticle v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) SIM_COHERENT buffer CountersRef { Counters v; };
UniformsRef g_u;
Vec4Ref g_pos, g_prev, g_rest_pos, g_delta, g_candidate_base, g_reset_from;
Vec2Ref g_uv;
ConstraintRef g_constraints;
Uvec2Ref g_color_range, g_tri_edges;
Vec4Ref g_hinges;
UintRef g_adj_offsets, g_adj_list, g_adj_mask, g_cell_count, g_cell_start, g_cell_particles, g_particle_cell, g_torn,
    g_scratch, g_cell_scatter, g_candidates;
Uvec4Ref g_triangles, g_compact_tmp, g_cell_pos;
Uvec4Ref g_hash_args;
UintRef g_contact_grid, g_contact_lists;
ContactRef g_contact;
CountersRef g_counters;

// The sheet workgroup `group` ticks, and the address of its slice of binding `binding`.
uint batchSheet(uint group) {
  return QueueRef(uint64_t(packUint2x32(BatchTableRef(packUint2x32(batch.table)).entry[SIM_BATCH_QUEUE].xy)))
      .sheet[batch.first + group];
}
uint64_t batchSlice(uint binding, uint sheet) {
  uvec4 e = BatchTableRef(packUint2x32(batch.table)).entry[binding];
  return packUint2x32(e.xy) + uint64_t(sheet) * packUint2x32(e.zw);
}
// Points every array at the slices of `sheet`.
void bindSheet(uint sheet) {
  g_u = UniformsRef(batchSlice(SIM_BIND_UNIFORMS, sheet));
  g_pos = Vec4Ref(batchSlice(SIM_BIND_POS, sheet));
  g_prev = Vec4Ref(batchSlice(SIM_BIND_PREV, sheet));
  g_rest_pos = Vec4Ref(batchSlice(SIM_BIND_REST, sheet));
  g_uv = Vec2Ref(batchSlice(SIM_BIND_UV, sheet));
  g_delta = Vec4Ref(batchSlice(SIM_BIND_DELTA, sheet));
  g_reset_from = Vec4Ref(batchSlice(SIM_BIND_RESET_FROM, sheet));
  g_candidate_base = Vec4Ref(batchSlice(SIM_BIND_CANDIDATE_BASE, sheet));
  g_constraints = ConstraintRef(batchSlice(SIM_BIND_CONSTRAINTS, sheet));
  g_color_range = Uvec2Ref(batchSlice(SIM_BIND_COLOR_RANGES, sheet));
  g_tri_edges = Uvec2Ref(batchSlice(SIM_BIND_TRI_EDGES, sheet));
  g_adj_offsets = UintRef(batchSlice(SIM_BIND_ADJ_OFFSETS, sheet));
  g_adj_list = UintRef(batchSlice(SIM_BIND_ADJ_LIST, sheet));
  g_adj_mask = UintRef(batchSlice(SIM_BIND_ADJ_MASK, sheet));
  g_cell_count = UintRef(batchSlice(SIM_BIND_CELL_COUNT, sheet));
  g_cell_start = UintRef(batchSlice(SIM_BIND_CELL_START, sheet));
  g_cell_particles = UintRef(batchSlice(SIM_BIND_CELL_PARTICLES, sheet));
  g_particle_cell = UintRef(batchSlice(SIM_BIND_PARTICLE_CELL, sheet));
  g_torn = UintRef(batchSlice(SIM_BIND_TORN, sheet));
  g_scratch = UintRef(batchSlice(SIM_BIND_SCRATCH, sheet));
  g_cell_scatter = UintRef(batchSlice(SIM_BIND_CELL_SCATTER, sheet));
  g_candidates = UintRef(batchSlice(SIM_BIND_CANDIDATES, sheet));
  g_triangles = Uvec4Ref(batchSlice(SIM_BIND_TRIANGLES, sheet));
  g_compact_tmp = Uvec4Ref(batchSlice(SIM_BIND_COMPACT_TMP, sheet));
  g_cell_pos = Uvec4Ref(batchSlice(SIM_BIND_CELL_POS, sheet));
  g_hash_args = Uvec4Ref(batchSlice(SIM_BIND_HASH_ARGS, sheet));
  g_counters = CountersRef(batchSlice(SIM_BIND_COUNTERS, sheet));
  g_hinges = Vec4Ref(batchSlice(SIM_BIND_HINGES, sheet));
  g_contact = ContactRef(batchSlice(SIM_BIND_CONTACT, sheet));
  g_contact_grid = UintRef(batchSlice(SIM_BIND_CONTACT_GRID, sheet));
  g_contact_lists = UintRef(batchSlice(SIM_BIND_CONTACT_LISTS, sheet));
}
#define u g_u.v
#define pos g_pos.v
#define prev g_prev.v
#define rest_pos g_rest_pos.v
#define uv g_uv.v
#define delta g_delta.v
#define reset_from g_reset_from.v
#define candidate_base g_candidate_base.v
#define constraints g_constraints.v
#define color_range g_color_range.v
#define tri_edges g_tri_edges.v
#define adj_offsets g_adj_offsets.v
#define adj_list g_adj_list.v
#define adj_mask g_adj_mask.v
#define cell_count g_cell_count.v
#define cell_start g_cell_start.v
#define cell_particles g_cell_particles.v
#define particle_cell g_particle_cell.v
#define torn g_torn.v
#define scratch g_scratch.v
#define cell_scatter g_cell_scatter.v
#define candidates g_candidates.v
#define triangles g_triangles.v
#define compact_tmp g_compact_tmp.v
#define cell_pos g_cell_pos.v
#define hash_args g_hash_args.v
#define counters g_counters.v
#define hinges g_hinges.v
#define contact_particles g_contact.v
#define contact_words g_contact_grid.v
#define contact_lists g_contact_lists.v
#else
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
layout(std430, set = 0, binding = SIM_BIND_PICK) SIM_COHERENT buffer PickBuffer { PickResult pick; };
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
layout(std430, set = 0, binding = SIM_BIND_HINGES) SIM_COHERENT buffer HingeBuffer { HingeState hinges[]; };
// Penetration-free contact (contact.glsl)
layout(std430, set = 0, binding = SIM_BIND_CONTACT_LISTS) SIM_COHERENT buffer ContactListBuffer {
  uint contact_lists[];
};
layout(std430, set = 0, binding = SIM_BIND_CONTACT) SIM_COHERENT buffer ContactBuffer {
  ContactParticle contact_particles[];
};
layout(std430, set = 0, binding = SIM_BIND_CONTACT_GRID) SIM_COHERENT buffer ContactGridBuffer {
  uint contact_words[];
};

#endif

// The contact's keys (SimUniforms::contact), checks and grid, the hinges' range and the walk's and
// crossing checks' arguments, each read whole: a fleet's lavapipe build (device addresses, Mesa
// 22.3) misreads components of one vector loaded apart
// (SpirvRules.NoSimShaderLoadsTwoComponentsOfAVectorApartByDeviceAddress)
ContactKeys contactKeys() { return u.contact; }
ContactChecks contactChecks() { return u.contact_check; }
ContactGrid contactGrid() { return u.contact_grid; }
HingeRange hingeKeys() { return u.hinge; }
uvec4 walkArgs() { return hash_args[SIM_CONTACT_WALK_ARGS]; }
uvec4 crossArgs() { return hash_args[SIM_CONTACT_CROSS_ARGS]; }
// The conditions this sheet's uniforms meet (stageConditions: what runs in a substep).
uint conditionsNow() {
  CreaseKeys crease = u.crease;
  return stageConditions(u.flags, u.grab_index, hingeKeys().count, crease.yield_angle, u.limit.reach,
                         contactKeys().radius, contactChecks().sweeps);
}

// Linear index of this invocation; grids wider than SIM_MAX_GROUPS_X spill into Y.
uint threadIndex() {
  return (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
}

// Linear index of this workgroup.
uint groupIndex() { return gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x; }

// Slot of the constraint that invocation t takes in a pass over `colour` (one invocation a
// constraint), or SIM_NONE beyond the colour's live count.
uint colourSlot(uint colour, uint t) {
  uvec2 range = color_range[colour];
  return t < range.y ? range.x + t : SIM_NONE;
}

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

// The mode of this substep in the per-colour passes (candidates_check has run).
uint collideModeNow() { return collideModeOf(counters.candidate_state, counters.candidate_flags.x != 0u); }

// Slots the tear compaction covers: constraints, triangles, and one end slot for the totals.
uint compactSlots() { return u.constraint_count + u.triangle_count + 1u; }

#ifdef SIM_BATCH_PASS
// A per-colour pass of a fleet: workgroup z works on the sheet at queue[batch.first + z], when the
// pass's gate takes it (BatchArgs: its conditions, SIM_LIVE_* in sim_config.h); the pass's own main()
// follows as simPassMain.
bool batchGateTakes() {
  if (batch.live == SIM_LIVE_RESET) return u.reset_active != 0u;
  if (u.reset_active != 0u || batch.substep >= substepCount(u.substeps)) return false;
  if (!runsWhen(batch.when, conditionsNow())) return false;
  switch (batch.live) {
  case SIM_LIVE_ITERATION:
    return batch.arg < u.iterations;
  case SIM_LIVE_HASH:
    return collideModeNow() != SIM_COLLIDE_CANDIDATES;
  case SIM_LIVE_COMPACTION:
    return counters.compact_dispatch.x != 0u;
  // Contact's indirect passes: those its own arguments give workgroups (contact_arm set them;
  // they stand through the substep)
  case SIM_LIVE_CONTACT_GRID:
    return contact_words[SIM_CONTACT_WORD_GRID] != 0u;
  case SIM_LIVE_CONTACT_WALK:
    return walkArgs().x != 0u;
  case SIM_LIVE_CONTACT_CROSS:
    return crossArgs().x != 0u;
  case SIM_LIVE_SWEEP:
    return batch.arg < contactChecks().sweeps;
  default:
    return true;
  }
}

// The batch's indirect argument `live` (SIM_BATCH_ARGS_* in sim_config.h) gets the workgroups of
// the full grid `full`: a sheet of the batch needs the pass.
void batchArmArgs(uint live, uint full) {
  UintRef args = UintRef(batchSlice(SIM_BATCH_ARGS, 0u));
  atomicMax(args.v[4u * live], args.v[4u * full]);
}

// The batch's indirect argument `live` covers a sheet's own grid `own` (x and y), when it has one.
void batchRaiseArgs(uint live, uvec4 own) {
  if (own.x == 0u) return;
  UintRef args = UintRef(batchSlice(SIM_BATCH_ARGS, 0u));
  atomicMax(args.v[4u * live], own.x);
  atomicMax(args.v[4u * live + 1u], own.y);
}

void simPassMain();
void main() {
  bindSheet(batchSheet(gl_WorkGroupID.z));
  if (batchGateTakes()) simPassMain(); // the whole workgroup takes the same branch
}
#define main simPassMain
#endif

#endif
