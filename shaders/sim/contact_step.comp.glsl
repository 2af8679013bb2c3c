#version 460
// Contact (contact.glsl), after contact_share: each particle's step cut to its pairs' half-spaces
// and its bound, then pushed (contactSlideStep).
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "contact.glsl"
#include "sim_common.glsl"

void main() {
  uint i = threadIndex();
  if (i >= p.count) return;
  VerletState st;
  st.position = pos[i];
  st.previous = prev[i];
  st = contactSlideStep(i, st, p.substep);
  pos[i] = st.position;
  prev[i] = st.previous;
}
