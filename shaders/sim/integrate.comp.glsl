#version 460
// Verlet integration with gravity, wind (and the air of the air pass) and damping; pins and the grab hold their
// particles, a toss places the released particle with its drag velocity. Workgroup size (sim_common.glsl declares it
// and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "sim_common.glsl"

void main() {
  uint i = threadIndex();
  // A new substep: no constraint torn in it yet, nothing to compact.
  if (i == 0u) {
    counters.torn_new = 0u;
    counters.compact_dispatch = uvec4(0u, 1u, 1u, 0u);
  }
  if (i >= p.count) return;
  uint s = p.substep;
  VerletState st =
      integrateParticle(i, pos[i], prev[i], rest_pos[i], uv[i].x, i == u.grab_index, u.grab_target[s], u.grab_prev[s],
                        u.hand, u.hand_motion, u.flags, u.gravity, windWithAir(u.wind[s], delta[i], u.flags),
                        u.wind_twist[s], substepDamping(u.damping, u.verlet, s), u.dt * u.dt);
  pos[i] = st.position;
  prev[i] = st.previous;
}
