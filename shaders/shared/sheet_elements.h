#pragma once
/// The CPU's view of a sheet for the shaders' own per-element bodies (shaders/shared/sim_bodies.h):
/// the sheet's arrays under the names the shaders give their buffers, so CpuSolver calls exactly
/// what the shaders' main()s call.
#include "shaderio.h"

namespace shaderio {

/// A sheet's arrays as the element bodies read them.
struct SheetElements {
  const SimUniforms& u;
  vec4* pos;
  vec4* prev;
  SharedWords torn; ///< read while markUnsupported marks edges no triangle holds

  const uvec2* tri_edges;
  HingeState* hinges;
  Counters& counters;

#include "sim_bodies.h"
#undef SIM_POSITION
};

} // namespace shaderio
