#version 460
// Small sheets: integration and every colour of every iteration in one workgroup, positions in
// shared memory, a workgroup barrier between colours instead of a dispatch and a pipeline
// barrier. Same per-particle and per-constraint maths, in the same order, as integrate + project.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_FUSED
#include "sim_common.glsl"
layout(push_constant) uniform PushBlock { SimPush p; };

shared vec4 s_pos[SIM_FUSED_MAX_PARTICLES];

void main() {
  uint lid = gl_LocalInvocationID.x;
  uint n = p.count;
  uint s = p.substep;
  // A new substep: no constraint torn in it yet, nothing to compact.
  if (lid == 0u) {
    counters.torn_new = 0u;
    counters.compact_dispatch = uvec4(0u, 1u, 1u, 0u);
  }
  // 1. Verlet integration (as integrate.comp)
  float dt2 = u.dt * u.dt;
  for (uint i = lid; i < n; i += SIM_WG_FUSED) {
    VerletState st = integrateParticle(pos[i], prev[i], rest_pos[i], uv[i].x, i == u.grab_index, u.grab_target[s],
                                       u.grab_prev[s], u.flags, u.gravity, u.wind[s], u.wind_twist[s], u.damping, dt2);
    s_pos[i] = st.pos;
    prev[i] = st.prev;
  }
  memoryBarrierShared();
  barrier();
  // 2. Gauss-Seidel over colours (as project.comp), a workgroup barrier after each colour
  for (uint it = 0u; it < u.iterations; ++it)
    for (uint c = 0u; c < u.color_count; ++c) {
      uvec2 range = color_range[c];
      for (uint t = lid; t < range.y; t += SIM_WG_FUSED) {
        Constraint k = constraints[range.x + t];
        PairDelta d = solveDistance(s_pos[k.a], s_pos[k.b], k.rest, u.stiffness[k.kind_id & SIM_KIND_MASK]);
        s_pos[k.a] += vec4(d.da, 0.0f);
        s_pos[k.b] += vec4(d.db, 0.0f);
      }
      memoryBarrierShared();
      barrier();
    }
  for (uint i = lid; i < n; i += SIM_WG_FUSED) pos[i] = s_pos[i];
}
