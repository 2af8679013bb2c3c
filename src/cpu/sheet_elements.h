#pragma once
/// The CPU's view of a sheet for the shaders' own per-element bodies (shaders/shared/sim_bodies.h):
/// the sheet's arrays under the names the shaders give their buffers, so CpuSolver calls exactly
/// what the shaders' main()s call.
#include <atomic>

#include "shaderio.h"

namespace shaderio {

/// GLSL's atomicExchange and atomicAdd on a word other threads of the pass may touch (relaxed: the
/// end of the parallel loop orders them, as a pipeline barrier does on the GPU).
inline uint atomicExchange(uint& word, uint value) {
  return std::atomic_ref<uint>(word).exchange(value, std::memory_order_relaxed);
}
inline uint atomicAdd(uint& word, uint value) {
  return std::atomic_ref<uint>(word).fetch_add(value, std::memory_order_relaxed);
}

/// A sheet's arrays as the element bodies read them.
struct SheetElements {
  const SimUniforms& u;
  vec4* pos;
  const vec4* prev;
  uint* torn;
  const uvec2* tri_edges;
  Counters& counters;

#define SIM_POSITION(j) pos[j]
#include "sim_bodies.h"
#undef SIM_POSITION
};

} // namespace shaderio
