#version 460
// The ground contact; with contact on, the particle's sums and share readied for the half-spaces'
// passes (contact_pass, contact_excess, contact_share), which contact_step's bounded step follows.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "contact.glsl"
#include "sim_common.glsl"
#include "sim_elements.glsl"

void main() {
  uint i = threadIndex();
  if (i >= p.count) return;
  VerletState st = floorContact(pos[i], prev[i], u.floor_y, u.restitution, u.friction);
  if (runsWhen(SIM_WHEN_CONTACT, conditionsNow())) contactSlideClear(i);
  pos[i] = st.position;
  prev[i] = st.previous;
}
