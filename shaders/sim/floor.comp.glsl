#version 460
// Applies the collision deltas (when collision is on), then the ground contact.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#include "sim_common.glsl"
layout(push_constant) uniform PushBlock { SimPush p; };

void main() {
  uint i = threadIndex();
  if (i >= p.count) return;
  vec4 q = pos[i];
  if ((u.flags & SIM_FLAG_COLLISION) != 0u && q.w > 0.0f) q += vec4(vec3(delta[i]), 0.0f);
  VerletState st = floorContact(q, prev[i], u.floor_y, u.restitution, u.friction);
  pos[i] = st.pos;
  prev[i] = st.prev;
}
