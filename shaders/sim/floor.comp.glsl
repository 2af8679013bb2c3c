#version 460
// Applies the collision deltas (when collision is on), then the ground contact.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "sim_common.glsl"
#include "sim_elements.glsl"

void main() {
  uint i = threadIndex();
  if (i >= p.count) return;
  VerletState st = floorParticle(pos[i], prev[i], vec3(delta[i]), u.flags, u.floor_y, u.restitution, u.friction);
  pos[i] = st.position;
  prev[i] = st.previous;
}
