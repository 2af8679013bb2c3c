// Self-collision maths shared by GLSL and C++: the spatial hash, the repulsion of a pair, and the
// rules of the collision candidate lists (SIM_CANDIDATE_* in sim_config.h). Included by xpbd.h.
#ifndef SIM_COLLISION_H
#define SIM_COLLISION_H
#include "exact_math.h"
#include "sim_types.h"

/// Integer cell of a position in the spatial hash, clamped to +-2^29 so that the conversion and the
/// differences of two cells stay within int range however far a particle has flown.
SIM_INLINE ivec3 cellOf(vec3 p, float inv_cell) {
  return ivec3(clamp(floor(p * inv_cell), vec3(-536870912.0f), vec3(536870912.0f)));
}

/// Hash bucket of a cell.
SIM_INLINE uint hashCell(ivec3 c, uint mask) {
  uint h = (uint(c.x) * 73856093u) ^ (uint(c.y) * 19349663u) ^ (uint(c.z) * 83492791u);
  return h & mask;
}

/// Repulsion of particle i away from j when closer than radius (half the overlap, scaled).
SIM_INLINE vec3 repulsion(vec3 pi, vec3 pj, float radius, float stiffness) {
  vec3 d = pi - pj;
  float d2 = dot3(d, d);
  vec3 r = vec3(0.0f);
  if (d2 < radius * radius && d2 > 1e-12f) {
    float len = simSqrt(d2);
    r = d * simDiv(stiffness * 0.5f * (radius - len), len);
  }
  return r;
}

/// Skin of the collision candidate lists (SIM_CANDIDATE_* in sim_config.h) for radius r and cells of
/// 1 / inv_cell: SIM_CANDIDATE_SKIN x r, at most 0.99 x (cell - r) so that the lists come from the 27
/// cells around a particle; 0 (no lists) below SIM_CANDIDATE_MIN_SKIN x r.
SIM_INLINE float candidateSkin(float r, float inv_cell) {
  float skin = min(SIM_CANDIDATE_SKIN * r, 0.99f * (simDiv(1.0f, inv_cell) - r));
  return skin >= SIM_CANDIDATE_MIN_SKIN * r ? skin : 0.0f;
}

/// True when the lists of `state` (x usable, y substeps since built, z substeps to wait, w the
/// bits of the search radius they were built with) hold the pairs within `search` (skin > 0).
SIM_INLINE bool candidatesCurrent(uvec4 state, float skin, float search) {
  return skin > 0.0f && state.x != 0u && state.w == floatBitsToUint(search);
}

/// True when a particle at p has travelled SIM_CANDIDATE_TRAVEL x skin or more from `base`, where it
/// was when the lists were built (the lists may then miss a pair).
SIM_INLINE bool travelledTooFar(vec3 p, vec3 base, float skin) {
  vec3 d = p - base;
  float travel = SIM_CANDIDATE_TRAVEL * skin;
  return !(dot3(d, d) < travel * travel);
}

/// True when the lists of `state` were outgrown within SIM_CANDIDATE_MIN_AGE substeps.
SIM_INLINE bool candidatesShortLived(uvec4 state) { return state.x != 0u && state.y < SIM_CANDIDATE_MIN_AGE; }

/// How a substep finds its collisions (SIM_COLLIDE_HASH, _LISTS or _BUILD), given the lists' state
/// and whether a particle has travelled SIM_CANDIDATE_TRAVEL x skin or more since they were built.
SIM_INLINE uint collideMode(uvec4 state, bool travelled, float skin, float search) {
  if (candidatesCurrent(state, skin, search) && !travelled) return SIM_COLLIDE_CANDIDATES;
  return skin > 0.0f && state.z == 0u && !candidatesShortLived(state) ? SIM_COLLIDE_BUILD : SIM_COLLIDE_HASH;
}

/// The lists' state after a substep in `mode` (overflow: a list outgrew SIM_CANDIDATE_CAPACITY).
SIM_INLINE uvec4 candidatesNextState(uvec4 state, uint mode, bool overflow, float search) {
  if (mode == SIM_COLLIDE_CANDIDATES) return uvec4(1u, state.y + 1u, 0u, state.w);
  if (mode == SIM_COLLIDE_BUILD)
    return uvec4(overflow ? 0u : 1u, 0u, overflow ? SIM_CANDIDATE_WAIT : 0u, floatBitsToUint(search));
  return uvec4(0u, 0u, candidatesShortLived(state) ? SIM_CANDIDATE_WAIT : max(state.z, 1u) - 1u, 0u);
}

/// Neighbour cell code of a cell offset o in {-1, 0, 1}^3: the order (dz, dy, dx) in which the
/// collision gather visits cells.
SIM_INLINE uint cellCode(ivec3 o) { return uint((o.z + 1) * 9 + (o.y + 1) * 3 + o.x + 1); }

#endif
