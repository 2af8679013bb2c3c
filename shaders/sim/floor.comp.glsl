#version 460
// The ground contact; with contact on, the contact push, and the step cut to the particle's bound
// (contactStep; contact.glsl).
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
  if (u.contact.x > 0.0f && contactBounded(st.position.w, i == u.grab_index, u.grab_target[p.substep].w))
    st = contactStep(st, vec3(contact_particles[i].start), vec3(contact_particles[i].push),
                     contact_particles[i].start.w, contactFrameNow());
  pos[i] = st.position;
  prev[i] = st.previous;
}
