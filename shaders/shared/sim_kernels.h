// The simulation's per-colour kernels, one row each, in the order a substep dispatches them
// (normals runs once a frame, reset during the animated reset). This table is their registry:
// C++ derives the pipelines (SimPipelines' members and makePassPipelines) from it and CMake the
// kernels a fleet also builds batched (shaders/CMakeLists.txt reads the rows), so a new kernel is
// its row here and its shader shaders/sim/<name>.comp.glsl. Keep one row per line, as written.
//
// X(name, push, per_invocation, batched)
//   name            shaders/sim/<name>.comp.glsl, SimPipelines::<name>
//   push            its push constants: SIM (SimPush), SCAN (ScanPush) or NONE
//   per_invocation  elements one invocation covers
//   batched         1: a fleet runs it once for the whole batch (built again with SIM_BATCH_PASS)
#ifndef SIM_KERNELS_H
#define SIM_KERNELS_H
#define SIM_KERNELS(X)                                                                                                 \
  X(air, SIM, 1, 1)                                                                                                    \
  X(integrate, SIM, 1, 1)                                                                                              \
  X(project, SIM, 1, 1)                                                                                                \
  X(candidates_check, SIM, 1, 1)                                                                                       \
  X(candidates_decide, SIM, 1, 1)                                                                                      \
  X(hash_count, SIM, 1, 1)                                                                                             \
  X(scan, SCAN, SIM_SCAN_PER_THREAD, 1)                                                                                \
  X(scan_add, SCAN, 1, 1)                                                                                              \
  X(hash_scatter, SIM, 1, 1)                                                                                           \
  X(hash_sort, SIM, 1, 1)                                                                                              \
  X(collide, SIM, 1, 1)                                                                                                \
  X(candidates_finish, SIM, 1, 1)                                                                                      \
  X(floor, SIM, 1, 1)                                                                                                  \
  X(tear_mark, SIM, 1, 1)                                                                                              \
  X(tear_unsupported, NONE, 1, 1)                                                                                      \
  X(tear_flags, NONE, 1, 1)                                                                                            \
  X(tear_compact, NONE, 1, 1)                                                                                          \
  X(normals, SIM, 1, 0)                                                                                                \
  X(reset, SIM, 1, 1)
#endif
