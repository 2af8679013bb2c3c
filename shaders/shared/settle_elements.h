#pragma once
/// The CPU's view of a sheet for the settle stage's per-edge body (shaders/shared/settle_bodies.h):
/// the arrays under the names the shaders give their buffers.
#include "shaderio.h"

namespace shaderio {

/// The arrays the settle body reads and writes, and its accessors of them.
struct SettleElements {
  const SimUniforms& u;
  vec4* pos;
  vec4* prev;
  const vec4* start;
  const vec4* push;
  const float* bound;
  const uint* half_start;
  const vec4* half_spaces;
  const float* half_slack;
  vec3 frame;

  vec3 settleStart(uint i) const { return vec3(start[i]); }
  vec3 settlePush(uint i) const { return vec3(push[i]); }
  float settleBound(uint i) const { return bound[i]; }
  uint halfFirst(uint i) const { return half_start[i]; }
  uint halfEnd(uint i) const { return half_start[i + 1u]; }
  SlideHalf halfSpace(uint k) const { return SlideHalf{half_spaces[k], half_slack[k]}; }
  vec3 settleFrame() const { return frame; }

#include "settle_bodies.h"
#undef SIM_POSITION
};

} // namespace shaderio
