// The passes of the simulation: one table each for its kernels, the stages of a substep and the
// dispatches of each stage, read by GLSL, C++ and CMake alike. What runs, in which order, how it
// is numbered, gated and timed is derived from these rows:
//   SIM_KERNELS    the pipelines (SimPipelines' members, makePassPipelines) and the kernels a fleet
//                  also builds batched (shaders/CMakeLists.txt reads the rows)
//   SIM_STAGES     the numbered passes of a substep: `tender diff` and a tick cut short
//                  (core/passes.h), the CPU tick's order (CpuSolver::tick), the fused tick's pass
//                  numbers (fused_tick.glsl)
//   SIM_DISPATCHES what the per-colour path records for each stage (gpu/substep_passes.cpp): the
//                  sheet's solver and a fleet alike
// Keep one row per line, as written. A new pass is a row here, its shader and its shared body:
// docs/ARCHITECTURE.md §3a has the recipe.
#ifndef SIM_PASSES_H
#define SIM_PASSES_H
#include "prelude.h"
#include "sim_config.h"

// The per-colour kernels, in the order a substep dispatches them (normals runs once a frame,
// reset during the animated reset).
// X(name, push, per_invocation, batched)
//   name            shaders/sim/<name>.comp.glsl, SimPipelines::<name>
//   push            its push constants: SIM (SimPush), SCAN (ScanPush) or NONE
//   per_invocation  elements one invocation covers
//   batched         1: a fleet runs it once for the whole batch (built again with SIM_BATCH_PASS)
#define SIM_KERNELS(X)                                                                                                 \
  X(contact_begin, SIM, 1, 1)                                                                                          \
  X(contact_clear, SIM, 1, 1)                                                                                          \
  X(contact_arm, SIM, 1, 1)                                                                                            \
  X(contact_grid_clear, SIM, 1, 1)                                                                                     \
  X(contact_count, SIM, 1, 1)                                                                                          \
  X(contact_scatter, SIM, 1, 1)                                                                                        \
  X(contact_cross, SIM, 1, 1)                                                                                          \
  X(contact_near, SIM, 1, 1)                                                                                           \
  X(contact_active, SIM, 1, 1)                                                                                         \
  X(contact_emit, SIM, 1, 1)                                                                                           \
  X(contact_walk, SIM, 1, 1)                                                                                           \
  X(contact_bound, SIM, 1, 1)                                                                                          \
  X(air, SIM, 1, 1)                                                                                                    \
  X(integrate, SIM, 1, 1)                                                                                              \
  X(candidates_check, SIM, 1, 1)                                                                                       \
  X(candidates_decide, SIM, 1, 1)                                                                                      \
  X(hash_count, SIM, 1, 1)                                                                                             \
  X(scan, SCAN, SIM_SCAN_PER_THREAD, 1)                                                                                \
  X(scan_add, SCAN, 1, 1)                                                                                              \
  X(hash_scatter, SIM, 1, 1)                                                                                           \
  X(hash_sort, SIM, 1, 1)                                                                                              \
  X(collide, SIM, 1, 1)                                                                                                \
  X(candidates_finish, SIM, 1, 1)                                                                                      \
  X(repel, SIM, 1, 1)                                                                                                  \
  X(project, SIM, 1, 1)                                                                                                \
  X(shorten, SIM, 1, 1)                                                                                                \
  X(limit, SIM, 1, 1)                                                                                                  \
  X(crease, SIM, 1, 1)                                                                                                 \
  X(floor, SIM, 1, 1)                                                                                                  \
  X(contact_pass, SIM, 1, 1)                                                                                           \
  X(contact_excess, SIM, 1, 1)                                                                                         \
  X(contact_share, SIM, 1, 1)                                                                                          \
  X(contact_step, SIM, 1, 1)                                                                                           \
  X(contact_settle_check, SIM, 1, 1)                                                                                   \
  X(contact_half_count, SIM, 1, 1)                                                                                     \
  X(contact_half_fill, SIM, 1, 1)                                                                                      \
  X(contact_settle, SIM, 1, 1)                                                                                         \
  X(tear_mark, SIM, 1, 1)                                                                                              \
  X(tear_unsupported, NONE, 1, 1)                                                                                      \
  X(tear_flags, NONE, 1, 1)                                                                                            \
  X(tear_compact, NONE, 1, 1)                                                                                          \
  X(normals, SIM, 1, 0)                                                                                                \
  X(reset, SIM, 1, 1)

// The stages of a substep, in the order they run; each is one numbered pass, or one per colour of
// each iteration. A tick numbers its passes substep x passesPerSubstep + the pass within the
// substep.
// X(name, id, repeat, condition)
//   name       what `tender diff` and TENDER_TEST_PLANT_ULP call it; PassKind::<name> in C++
//   id         its place in this table (0u, 1u, ...); SIM_STAGE_<name>
//   repeat     ONCE, or COLOUR: once per colour of each iteration
//   condition  ALWAYS, or COLLISION: only while collision is on
#define SIM_STAGES(X)                                                                                                  \
  X(integrate, 0u, ONCE, ALWAYS)                                                                                       \
  X(collide, 1u, ONCE, COLLISION)                                                                                      \
  X(project, 2u, COLOUR, ALWAYS)                                                                                       \
  X(shorten, 3u, COLOUR, ALWAYS)                                                                                       \
  X(limit, 4u, ONCE, ALWAYS)                                                                                           \
  X(crease, 5u, ONCE, ALWAYS)                                                                                          \
  X(floor, 6u, ONCE, ALWAYS)                                                                                           \
  X(settle, 7u, ONCE, ALWAYS)                                                                                          \
  X(tear, 8u, ONCE, ALWAYS)
#define SIM_STAGE_COUNT 9u

// The dispatches of each stage, in the order the per-colour path records them (a barrier after
// each). The fused tick and the CPU run the same bodies in the same order.
// X(stage, kernel, elements, grid, gate, needs, category)
//   stage     its row in SIM_STAGES
//   kernel    its row in SIM_KERNELS (scan: a scan of several blocks adds scan and scan_add)
//   elements  what it covers and its push constants: PARTICLES, COLOUR (the stage's colour),
//             HINGES, CONSTRAINTS, ONE (one invocation), HASH_ARGS (one invocation, the hash's
//             arguments), RINGS (one workgroup a sheet, a dispatch for each limitRingsPerDispatch
//             rings of the stretch limit), HASH_CELLS and TEAR_SLOTS (a scan of the hash's cells or of the
//             compaction's slots), INDIRECT (the grid's arguments, no push constants); contact's:
//             TRIANGLES (the triangle slots), CONTACT_SLOTS (whatever its clearing covers),
//             CONTACT_BUCKETS (its grid's buckets and their end),
//             CONTACT_BOXES (triangle slots, then edges), CONTACT_QUERIES (particles, then
//             edges), CONTACT_CELLS (a scan of its grid's buckets), CONTACT_ACTIVE (the queries
//             and their end, from the scratch offset of their flags) and CONTACT_ACTIVE_CELLS (a
//             scan of those flags); the settle's: CONTACT_HALF_CELLS (a scan of the particles'
//             half-space counts) and SWEEPS (the colours with structural edges, once each sweep:
//             SimPush.first the sweep)
//   grid      Threads (from the elements), Hash (the live hash arguments candidates_decide
//             copies), Contact (the live arguments of contact's grid passes contact_arm copies:
//             none in a substep that does not build the grid), Walk (contact_walk's, over the
//             queries with pairs in their lists: none in a substep that builds them), Cross
//             (contact_cross's, over the triangles: none in a substep whose crossing check looks
//             at no triangle), Named (contact_emit's: the queries with pairs in their lists),
//             Settle (the settle's half-spaces' passes: the named queries' grid, none in a substep
//             with no edge over the limit), Sweep (a settle sweep's, each colour's grid that of the largest:
//             none after a sweep that moved nothing) or
//             Compaction (the tear compaction's arguments): gpu::Grid
//   gate      the sheets of a fleet that run it: SIM_GATE_<gate> (sim_config.h)
//   needs     ALWAYS, AIR (the sheet has air), CREASE (the sheet has hinges and creases), LIMIT
//             (the sheet has a stretch limit), SHORTEN (the limit shortens edges: limitShortens),
//             CONSTRAINTS (the sheet has constraints), CONTACT (contact is on: a sheet alone,
//             or any sheet of a fleet) or SETTLE (contact is on with the settle's
//             sweeps: SubstepPlan::sweeps)
//   category  its timestamp category (gpu::PassCategory k<category>)
#define SIM_DISPATCHES(X)                                                                                              \
  X(integrate, contact_begin, ONE, Threads, CONTACT, CONTACT, Contact)                                                 \
  X(integrate, contact_clear, CONTACT_SLOTS, Threads, CONTACT, CONTACT, Contact)                                       \
  X(integrate, contact_arm, ONE, Threads, CONTACT, CONTACT, Contact)                                                   \
  X(integrate, contact_grid_clear, CONTACT_BUCKETS, Contact, CONTACT_GRID, CONTACT, Contact)                           \
  X(integrate, contact_count, CONTACT_BOXES, Contact, CONTACT_GRID, CONTACT, Contact)                                  \
  X(integrate, scan, CONTACT_CELLS, Contact, CONTACT_GRID, CONTACT, Contact)                                           \
  X(integrate, contact_scatter, CONTACT_BOXES, Contact, CONTACT_GRID, CONTACT, Contact)                                \
  X(integrate, contact_cross, TRIANGLES, Cross, CONTACT_CROSS, CONTACT, Contact)                                       \
  X(integrate, contact_near, CONTACT_QUERIES, Contact, CONTACT_GRID, CONTACT, Contact)                                 \
  X(integrate, contact_active, CONTACT_ACTIVE, Contact, CONTACT_GRID, CONTACT, Contact)                                \
  X(integrate, scan, CONTACT_ACTIVE_CELLS, Contact, CONTACT_GRID, CONTACT, Contact)                                    \
  X(integrate, contact_emit, CONTACT_ACTIVE, Contact, CONTACT_GRID, CONTACT, Contact)                                  \
  X(integrate, contact_walk, CONTACT_QUERIES, Walk, CONTACT_WALK, CONTACT, Contact)                                    \
  X(integrate, contact_bound, PARTICLES, Threads, CONTACT, CONTACT, Contact)                                           \
  X(integrate, air, PARTICLES, Threads, AIR, AIR, Integrate)                                                           \
  X(integrate, integrate, PARTICLES, Threads, TICK, ALWAYS, Integrate)                                                 \
  X(collide, candidates_check, PARTICLES, Threads, COLLISION, ALWAYS, Hash)                                            \
  X(collide, candidates_decide, HASH_ARGS, Threads, COLLISION, ALWAYS, Hash)                                           \
  X(collide, hash_count, PARTICLES, Hash, HASH, ALWAYS, Hash)                                                          \
  X(collide, scan, HASH_CELLS, Hash, HASH, ALWAYS, Hash)                                                               \
  X(collide, hash_scatter, PARTICLES, Hash, HASH, ALWAYS, Hash)                                                        \
  X(collide, hash_sort, PARTICLES, Hash, HASH, ALWAYS, Hash)                                                           \
  X(collide, collide, PARTICLES, Threads, COLLISION, ALWAYS, Collide)                                                  \
  X(collide, candidates_finish, ONE, Threads, COLLISION, ALWAYS, Collide)                                              \
  X(collide, repel, PARTICLES, Threads, COLLISION, ALWAYS, Collide)                                                    \
  X(project, project, COLOUR, Threads, ITERATION, ALWAYS, Project)                                                     \
  X(shorten, shorten, COLOUR, Threads, SHORTEN, SHORTEN, Project)                                                      \
  X(limit, limit, RINGS, Threads, LIMIT, LIMIT, Project)                                                               \
  X(crease, crease, HINGES, Threads, CREASE, CREASE, Project)                                                          \
  X(floor, floor, PARTICLES, Threads, TICK, ALWAYS, Floor)                                                             \
  X(floor, contact_pass, CONTACT_QUERIES, Named, CONTACT, CONTACT, Floor)                                              \
  X(floor, contact_excess, CONTACT_QUERIES, Named, CONTACT, CONTACT, Floor)                                            \
  X(floor, contact_share, CONTACT_QUERIES, Named, CONTACT, CONTACT, Floor)                                             \
  X(floor, contact_step, PARTICLES, Threads, CONTACT, CONTACT, Floor)                                                  \
  X(settle, contact_settle_check, CONSTRAINTS, Threads, SETTLE, SETTLE, Floor)                                         \
  X(settle, contact_half_count, CONTACT_QUERIES, Settle, SETTLE, SETTLE, Floor)                                        \
  X(settle, scan, CONTACT_HALF_CELLS, Threads, SETTLE, SETTLE, Floor)                                                  \
  X(settle, contact_half_fill, CONTACT_QUERIES, Settle, SETTLE, SETTLE, Floor)                                         \
  X(settle, contact_settle, SWEEPS, Sweep, SETTLE, SETTLE, Floor)                                                      \
  X(tear, tear_mark, CONSTRAINTS, Threads, TICK, CONSTRAINTS, Tear)                                                    \
  X(tear, tear_unsupported, INDIRECT, Compaction, COMPACTION, CONSTRAINTS, Tear)                                       \
  X(tear, tear_flags, INDIRECT, Compaction, COMPACTION, CONSTRAINTS, Tear)                                             \
  X(tear, scan, TEAR_SLOTS, Compaction, COMPACTION, CONSTRAINTS, Tear)                                                 \
  X(tear, tear_compact, INDIRECT, Compaction, COMPACTION, CONSTRAINTS, Tear)

#define SIM_STAGE_ID(name, id, repeat, condition) SIM_CONST uint SIM_STAGE_##name = id;
SIM_STAGES(SIM_STAGE_ID)
#undef SIM_STAGE_ID

// A stage's condition and repeat as values (stagePasses)
#define SIM_STAGE_RUNS_ALWAYS true
#define SIM_STAGE_RUNS_COLLISION false
#define SIM_STAGE_REPEATS_ONCE false
#define SIM_STAGE_REPEATS_COLOUR true

/// Passes stage `stage` numbers in a substep of `iterations` x `colors` projections, with
/// collision on or off (0: it does not run).
SIM_INLINE uint stagePasses(uint stage, uint iterations, uint colors, bool collision) {
  uint passes = 0u;
#define SIM_STAGE_PASSES(name, id, repeat, condition)                                                                  \
  if (stage == id && (SIM_STAGE_RUNS_##condition || collision))                                                        \
    passes = SIM_STAGE_REPEATS_##repeat ? iterations * colors : 1u;
  SIM_STAGES(SIM_STAGE_PASSES)
#undef SIM_STAGE_PASSES
  return passes;
}

/// Number within its substep of the first pass of stage `stage` (of SIM_STAGE_COUNT: the passes of
/// a substep).
SIM_INLINE uint stageFirstPass(uint stage, uint iterations, uint colors, bool collision) {
  uint first = 0u;
  for (uint k = 0u; k < stage; ++k) first += stagePasses(k, iterations, colors, collision);
  return first;
}

/// The grid of `groups` workgroups: at most SIM_MAX_GROUPS_X in x, the rest spilled into y (the
/// shaders linearise the group index, threadIndex in sim_common.glsl).
SIM_INLINE uvec2 groupGrid(uint groups) {
  uint gx = min(groups, uint(SIM_MAX_GROUPS_X));
  return uvec2(gx, gx > 0u ? (groups + gx - 1u) / gx : 0u);
}

/// Passes one substep numbers.
SIM_INLINE uint passesPerSubstep(uint iterations, uint colors, bool collision) {
  return stageFirstPass(SIM_STAGE_COUNT, iterations, colors, collision);
}
#endif
