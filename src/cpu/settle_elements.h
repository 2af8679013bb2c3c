#pragma once
/// The CPU's view of a sheet for the settle stage's per-edge body (shaders/shared/settle_bodies.h):
/// the arrays under the names the shaders give their buffers.
#include "shaderio.h"

namespace shaderio {

/// The arrays the settle body reads and writes.
struct SettleElements {
  const SimUniforms& u;
  vec4* pos;
  const vec4* settle_start;
  const vec4* settle_push;
  const float* settle_bound;
  const uint* half_start;
  const vec4* half_spaces;
  const float* half_slack;
  vec3 settle_frame;
  uint settle_substep;

#include "settle_bodies.h"
#undef SIM_POSITION
};

} // namespace shaderio
