// The settle stage's per-edge body, shared by GLSL and C++ (settle_elements.h beside it includes it
// inside a struct whose members bear the buffers' names): after the contact's cut and push, each
// structural edge longer than the stretch limit is shortened from both ends within what the
// contact lets each end's step go. It reads u (SimUniforms), the positions through SIM_POSITION(j)
// and the previous positions `prev` (it writes both), and through functions each side defines: for
// particle i where it started the substep (settleStart), its push (settlePush), its ball
// (settleBound), its half-spaces (halfSpace(k) for k from halfFirst(i) to halfEnd(i)), and the
// substep's frame (settleFrame, contactFrame). The half-spaces are listed by particle, counted,
// scanned and filled (SIM_CONTACT_HALF_CAPACITY a particle on average); a particle whose list ends
// past them is not moved.
//
// Why the contact's guarantee stands: a particle's half-spaces and ball (the cut's, slideStep) are
// convex and hold the zero step, and the particle's step after the cut keeps them; each move here
// goes only as far as halfSpaceRoom and ballRoom let the step go, or takes the step back towards
// zero, so every step still keeps them. The rooms are minimums over a particle's half-spaces: the
// order they are listed in changes no bit.
#ifndef SIM_SETTLE_BODIES_H
#define SIM_SETTLE_BODIES_H

#ifndef SIM_POSITION
#define SIM_POSITION(j) pos[j]
#endif

/// Particle i's step in the substep less the frame and its push: what its half-spaces and ball hold.
SIM_INLINE vec3 settleStep(uint i) { return vec3(SIM_POSITION(i)) - (settleStart(i) + settleFrame()) - settlePush(i); }

/// True when particle i is free to move in the settle in substep s: the contact bounds it
/// (contactBounded), and the held grab only while the hand is closed (HandKeys::reach). A closed
/// hand holds the ball, not the point: where a neighbour pressed in the ball cannot follow, the grab
/// gives way within its own half-spaces and ball rather than stretch their edge to its tear length
/// (the hand places it again at the next substep). An open hand's grab stays where the hand has it.
SIM_INLINE bool settleFree(uint i, uint s) {
  vec4 p = SIM_POSITION(i), target = u.grab_target[s]; // whole (contactSlideStep says why)
  HandKeys hand = u.hand;
  return contactBounded(p.w, i == u.grab_index, target.w) && (p.w > 0.0f || hand.reach > 0.0f);
}

/// True when the settle may move particle i in substep s: free, and its half-spaces all listed.
SIM_INLINE bool settleMovable(uint i, uint s) {
  return settleFree(i, s) && halfEnd(i) <= SIM_CONTACT_HALF_CAPACITY * u.particle_count;
}

/// True when constraint c is a structural edge longer than the stretch limit, short of its tear
/// length, with a free end: the edges the settle may work on in substep s (before the half-spaces
/// are listed: without any, the stage moves nothing and is skipped).
SIM_INLINE bool settleOver(Constraint c, uint s) {
  if ((c.kind_id & SIM_KIND_MASK) != SIM_KIND_STRUCTURAL) return false;
  vec4 pa = SIM_POSITION(c.a), pb = SIM_POSITION(c.b);
  vec3 d = vec3(pb) - vec3(pa);
  return dot3(d, d) > u.limit.reach * u.limit.reach &&
         !shouldTear(pa, pb, c.rest, SIM_KIND_STRUCTURAL, u.tear_factor, u.tear_kinds) &&
         (settleFree(c.a, s) || settleFree(c.b, s));
}

/// Moves particle i by up to `want` along the unit `dir`, as far as its ball and half-spaces let
/// its step go; how far it moved. Its previous position moves by as much, so the move adds no
/// speed, as the stretch limit's places add none: taken as a step, each substep's shortening sped
/// the ends of the edges it held together, and a `crumple` sheet hanging with soft edges
/// (`stiffness` 0, the limit and the settle holding them every substep) was pumped to 9 units/s.
SIM_INLINE float settleMove(uint i, vec3 dir, float want) {
  if (!(want > 0.0f)) return 0.0f;
  vec3 s = settleStep(i), d = dir * want;
  float s_len = simSqrt(dot3(s, s)), d_len = simSqrt(dot3(d, d));
  float t = ballRoom(s, d, settleBound(i));
  for (uint k = halfFirst(i); k < halfEnd(i); ++k) t = min(t, halfSpaceRoom(halfSpace(k), s, s_len, d, d_len));
  vec4 moved = vec4(dir * (want * t), 0.0f);
  SIM_POSITION(i) = SIM_POSITION(i) + moved;
  prev[i] = prev[i] + moved;
  return want * t;
}

/// Takes back particle i's step (towards where it started, with the frame and its push) by up to
/// what shortens its edge by `want`, when the step went away along -`dir`; the shortening.
SIM_INLINE float settleBack(uint i, vec3 dir, float want) {
  vec3 s = settleStep(i);
  float rate = -dot3(s, dir); // what taking the whole step back shortens the edge by
  if (!(want > 0.0f) || !(rate > 0.0f)) return 0.0f;
  float l = min(1.0f, simDiv(want, rate));
  SIM_POSITION(i) = SIM_POSITION(i) - vec4(s * l, 0.0f);
  return rate * l;
}

/// The settle on constraint c in substep s, in the colour order of the projection (no two of a
/// colour share a particle): a structural edge longer than the stretch limit (and short of its
/// tear length) is shortened by each end's move along it (half each, what one cannot take offered
/// to the other), then by the ends' steps taken back. False when it left the edge alone (nothing
/// moved): a sweep in which every edge is left alone is the last that moves anything.
SIM_INLINE bool settleConstraint(Constraint c, uint s) {
  if ((c.kind_id & SIM_KIND_MASK) != SIM_KIND_STRUCTURAL) return false;
  LimitKeys limit = u.limit;
  vec4 pa = SIM_POSITION(c.a), pb = SIM_POSITION(c.b);
  vec3 d = vec3(pb) - vec3(pa);
  float len2 = dot3(d, d);
  // Most edges are within the limit: that test first, the tear's square root after
  if (!(len2 > limit.reach * limit.reach)) return false;
  if (shouldTear(pa, pb, c.rest, SIM_KIND_STRUCTURAL, u.tear_factor, u.tear_kinds)) return false;
  bool ma = settleMovable(c.a, s), mb = settleMovable(c.b, s);
  if (!ma && !mb) return false;
  float len = simSqrt(len2), over = len - limit.reach;
  vec3 e = d * simDiv(1.0f, len);
  float got_a = ma ? settleMove(c.a, e, mb ? 0.5f * over : over) : 0.0f;
  float got_b = mb ? settleMove(c.b, -e, over - got_a) : 0.0f;
  float got_a2 = ma ? settleMove(c.a, e, over - got_a - got_b) : 0.0f;
  float left = over - got_a - got_b - got_a2;
  if (!(left > 0.0f)) return true;
  float back_a = ma ? settleBack(c.a, e, mb ? 0.5f * left : left) : 0.0f;
  left -= back_a;
  float back_b = mb ? settleBack(c.b, -e, left) : 0.0f;
  left -= back_b;
  if (ma) settleBack(c.a, e, left);
  return true;
}
#endif
