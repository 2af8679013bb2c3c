// Penetration-free self-contact, shared by GLSL and C++: the bounded step of a particle, from the
// distances between the sheet's primitives (distance.h; included at the end of xpbd.h, after
// VerletState).
//
// The guarantee (the conservative bound of Offset Geometric Contact, Chen et al. 2025): at the
// start of a substep every particle v gets a bound b(v) = fraction x d(v), fraction < 1/2, where
// d(v) is the smallest of the contact radius r and the distances
//   - from v to every triangle that does not hold v,
//   - from every triangle that holds v to every particle it does not hold,
//   - from every edge that holds v to every edge that shares no particle with it.
// No particle then ends the substep farther than b(v) from where it started (boundedStep). Take a
// particle v and a triangle f it is not part of, d apart: v moves at most fraction x d, and each
// corner of f at most fraction x d too (f holds that corner and is d from v), so every point of f
// (a convex combination of its corners) moves at most fraction x d. Along the straight way from
// the start to the end of the substep the two stay more than (1 - 2 fraction) d > 0 apart: v never
// reaches f. Two edges likewise. A triangle can only come to cross another by a particle passing
// a triangle or an edge passing an edge, so a sheet that starts a substep without crossing itself
// ends it without. Pairs farther apart than r are not searched: they move at most 2 fraction r < r
// towards each other. The grab is bounded too (contactBounded): it follows the hand no faster than
// its bound; a pinned particle does not move.
// The bound holds in a frame that moves with the sheet: a pair's distance falls by at most the
// largest difference of its particles' displacements, so a translation t common to every particle
// can be taken out of each step first: no particle ends farther than b(v) from its start + t
// (contactFrame picks t from how the sheet moved in the last substep: the motion every particle
// shares, none while one rests, a pinned one included). A sheet falling or flying as a whole is not
// held back, and with every start + t above the floor the floor stays out of the way.
// Floats round: stepBound takes a margin m, far above the rounding, off d, so pairs close in on
// m and stop there. The push that parts pairs closer than the thickness moves a particle on top of
// its bound, by at most SIM_CONTACT_PUSH_FRACTION x (d(v) - m/2) (contactPushWithin). A particle's
// push is the mean of all its pairs' pushes, so it may carry the particle towards a primitive other
// than the one a pair parts it from; the push's own margin keeps that from closing a pair substep
// after substep: with 0.4 (d - m) + 0.1 (d - m/2) on either side a pair d >= m apart keeps 0.9 m,
// one between m/2 and m, whose half-spaces let no step towards the other (below), moves 0.1 (d - m/2)
// a side at most and keeps 0.8 d + 0.1 m >= m/2, and one closer than m/2 (only a sheet that starts
// so) is not pushed and does not close. No pair ends a substep closer
// than the least of its distance at the start and m/2. (A push cut to 0.1 d alone let a pair
// pressed below m close by a fifth each substep, towards touching.)
// The bound need not hold along a pair, only across it (slideConstraint has why): a pair d < r
// apart sets each of its particles a half-space, towards the other primitive along the pair's
// normal by at most fraction x (d - m) (nothing within the margin), and along the planes nothing;
// the ball of fraction x
// (r - m) (slideBound) keeps the pairs farther than r apart. So a particle pressed on a layer
// slides along it as fast as a free particle moves, where b(v) above held it to a fraction of its
// distance in every direction. The steps are cut after the floor (slideStep): each step's excess
// beyond its half-spaces (the mean over its pairs) taken out, the rest cut to the largest share
// that keeps every one (they hold the zero step), then to the ball. Before that, a tenth of each
// step's excess beyond a half-space is passed on to the other primitive of its pair (contactPassed):
// what a particle is passed joins its step before its own half-spaces and ball cut it, so every
// step is still cut and the proof holds as it is, and a pull against a layer moves the layer (without
// speeding it up: passedState).
#ifndef SIM_CONTACT_H
#define SIM_CONTACT_H
#include "distance.h"
#include "exact_math.h"

/// The push that parts a contact pair closer than `thickness` (x: its four particles, their
/// inverse masses in w; c: pointTriangle or segmentSegment of them): each particle's share of the
/// projection of |sum w x| >= thickness, in k. Zero when the pair is apart, touches exactly, or
/// cannot move.
SIM_INLINE vec3 contactPush(vec4 x0, vec4 x1, vec4 x2, vec4 x3, NearestPoints c, float thickness, uint k) {
  float wsum = c.w.x * c.w.x * x0.w + c.w.y * c.w.y * x1.w + c.w.z * c.w.z * x2.w + c.w.w * c.w.w * x3.w;
  if (!(c.d2 < thickness * thickness) || !(c.d2 > 0.0f) || !(wsum > 0.0f)) return vec3(0.0f);
  vec3 sep = vec3(x0) * c.w.x + vec3(x1) * c.w.y + vec3(x2) * c.w.z + vec3(x3) * c.w.w;
  float len = simSqrt(c.d2);
  float wk = k == 0u ? c.w.x * x0.w : (k == 1u ? c.w.y * x1.w : (k == 2u ? c.w.z * x2.w : c.w.w * x3.w));
  return sep * simDiv((thickness - len) * wk, len * wsum);
}

/// The step bound of a particle whose nearest primitive is d = sqrt(nearest2) away (at most the
/// contact radius): `fraction` of d less the margin m = SIM_CONTACT_MARGIN x radius, zero within the
/// margin. Two primitives so bounded close in on the margin without reaching it; pressed
/// together, they stop there (the rounding of the positions is far below m), and only their push
/// parts them.
SIM_INLINE float stepBound(float nearest2, float radius, float fraction) {
  return fraction * max(simSqrt(nearest2) - SIM_CONTACT_MARGIN * radius, 0.0f);
}

/// A particle's push (contactAverage) cut to SIM_CONTACT_PUSH_FRACTION of the distance to its
/// nearest primitive, sqrt(nearest2), less half the margin of contact radius `radius`: it moves the
/// particle on top of its bound (slideStep), and with the bounds' fraction below 1/2 no pair
/// ends a substep closer than the least of its distance at the start and half the margin.
SIM_INLINE vec3 contactPushWithin(vec3 push, float nearest2, float radius) {
  float most = SIM_CONTACT_PUSH_FRACTION * max(simSqrt(nearest2) - 0.5f * SIM_CONTACT_MARGIN * radius, 0.0f);
  float l2 = dot3(push, push);
  return l2 > most * most ? push * simDiv(most, simSqrt(l2)) : push;
}

/// The reach of the pair lists of contact radius `radius`: they hold the pairs closer than this.
SIM_INLINE float contactReach(float radius) { return radius * (1.0f + SIM_CONTACT_SKIN); }

/// The reach of the pairs a repair of the lists looks for (the pairs with a particle that travelled
/// beyond contactTravel; CpuContact): a repaired pair's particles may have been up to two travels
/// apart already when it was looked at, so it closes by up to four before the lists are looked at
/// again, and 4 x SIM_CONTACT_TRAVEL < 2 skins.
SIM_INLINE float contactRepairReach(float radius) { return radius * (1.0f + 2.0f * SIM_CONTACT_SKIN); }

/// How far a particle may travel from where it was when the pair lists were built before they are
/// built again: under half the skin, so that every pair closer than the radius is in the lists (two
/// primitives close in by at most twice this, plus a rounding far below the rest of the skin).
SIM_INLINE float contactTravel(float radius) { return SIM_CONTACT_TRAVEL * SIM_CONTACT_SKIN * radius; }

/// True when the pair lists are built again: the particles' displacements since they were built
/// (componentwise lowest `lo` and highest `hi`) no longer all lie within contactTravel of one
/// point, the box's middle (a motion they share changes no pair's distance). NaN builds them.
SIM_INLINE bool listsOutgrown(vec3 lo, vec3 hi, float radius) {
  vec3 reach = (hi - lo) * 0.5f;
  float travel = contactTravel(radius);
  return !(dot3(reach, reach) < travel * travel);
}

/// The bits of a float in an order that is the floats' order (unsigned): minimums and maximums of
/// them, atomic on the GPU, give the same bits in any order.
SIM_INLINE uint orderedBits(float f) {
  uint b = floatBitsToUint(f);
  return (b & 0x80000000u) != 0u ? ~b : b | 0x80000000u;
}
SIM_INLINE float orderedFloat(uint o) { return uintBitsToFloat((o & 0x80000000u) != 0u ? o & 0x7FFFFFFFu : ~o); }

/// The translation taken out of every step of the substep before the bound (the frame in the proof
/// above), from every particle's step in the last substep (componentwise lowest `lo` and
/// highest `hi`) and the lowest start of one above the floor, `lowest` (>= 0): the point of the box
/// [lo, hi] nearest to no step, raised so that no start + it goes below the floor. Each component
/// lies between 0 and every particle's last step, and a step cut to its bound ends between the frame
/// and the particle's own step, so a particle that goes on moving with the sheet is carried no
/// farther than its own step along any axis; while one particle rests the frame is none, and a
/// sheet falling as a whole falls at least as fast as its slowest particle. `scale` carries the last
/// substep's steps to this substep's length (contactFrameScale: a tick whose substeps are longer
/// or shorter than the last tick's).
SIM_INLINE vec3 contactFrame(vec3 lo, vec3 hi, float lowest, float scale) {
  if (scale != 1.0f) {
    lo = lo * scale;
    hi = hi * scale;
  }
  vec3 t = vec3(lo.x > 0.0f ? lo.x : (hi.x < 0.0f ? hi.x : 0.0f), lo.y > 0.0f ? lo.y : (hi.y < 0.0f ? hi.y : 0.0f),
                lo.z > 0.0f ? lo.z : (hi.z < 0.0f ? hi.z : 0.0f));
  t.y = max(t.y, -lowest);
  return dot3(t, t) < 1e30f ? t : vec3(0.0f);
}

/// contactFrame's scale in substep s: the first substep's velocity rescale (SimUniforms::verlet.rescale,
/// this substep's length over the last tick's, 0 when they are the same), else 1.
SIM_INLINE float contactFrameScale(VerletKeys verlet, uint s) {
  return s == 0u && verlet.rescale > 0.0f ? verlet.rescale : 1.0f;
}

/// Where a particle that moved from x0 to x this substep ends when its step may not exceed
/// `bound`: x, or the point `bound` from x0 towards x.
SIM_INLINE vec3 boundedStep(vec3 x0, vec3 x, float bound) {
  vec3 d = x - x0;
  float l2 = dot3(d, d);
  if (!(l2 > bound * bound)) return x;
  return x0 + d * simDiv(bound, simSqrt(l2));
}

/// True when a particle's substep is cut to its bound (slideStep): a free particle (inverse mass
/// `w` > 0) and the grabbed one while the user places it (`grab_w`: its grab_target.w, 1 held, 2
/// tossed). The grab follows the hand as fast as its bound lets it and no faster, so no hand can
/// carry the sheet through itself; a pinned particle does not move.
SIM_INLINE bool contactBounded(float w, bool is_grabbed, float grab_w) {
  return w > 0.0f || (is_grabbed && grab_w > 0.5f);
}

/// A particle's substep with contact, its step less the frame ending at `target` (where its pairs'
/// half-spaces cut it: slideTarget) before it is cut to `bound` (boundedStep from x0 + frame); then
/// the push moves it without speeding it up. A step cut short keeps the particle's speed at most,
/// along the step it made: the contact never adds energy.
SIM_INLINE VerletState contactStepTo(VerletState st, vec3 target, vec3 x0, vec3 push, float bound, vec3 frame) {
  vec3 p = vec3(st.position), q = vec3(st.previous);
  vec3 x = boundedStep(x0 + frame, target, bound);
  if (x != p) {
    vec3 step = x - x0, v = p - q;
    float s2 = dot3(step, step), v2 = dot3(v, v);
    q = s2 > v2 ? x - step * simDiv(simSqrt(v2), simSqrt(s2)) : x0;
  }
  VerletState r;
  r.position = vec4(x + push, st.position.w);
  r.previous = vec4(q + push, st.previous.w);
  return r;
}

/// The step bound of a particle whose nearest primitive is sqrt(nearest2) away, in every direction:
/// stepBound of the radius (the pairs closer bound the step along their normals: slideConstraint,
/// within the margin too), or none where it touches a primitive (no normal says which way is away).
SIM_INLINE float slideBound(float nearest2, float radius, float fraction) {
  return nearest2 > 0.0f ? stepBound(radius * radius, radius, fraction) : 0.0f;
}

/// The half-space a contact pair sets one of its particles' steps in: h.xyz the unit normal on the
/// particle's side, h.w the most the step may go against it (h.w < 0: none), and `slack` how far
/// the normal may be off from rounding (per unit of the step's length), which the step's length
/// times it takes from what the step may go (slideAgainst).
struct SlideHalf {
  vec4 h;
  float slack;
};

/// The half-space contact pair c (x: its particles; `edge`: two edges, else a particle and a
/// triangle) 0 < d < radius apart sets its particle k in: the normal from the other primitive
/// towards k's, and fraction x (d - m), none within the margin m: a pair pressed closer than m may
/// part and slide, not close (a bound of zero there held its particles in every direction, so
/// a particle pressed on a layer stayed until its push parted it, a tenth of d - m/2 a substep).
/// Why it holds: the primitives are convex, so every corner of k's lies beyond the plane through its
/// nearest point normal to the pair's, and every corner of the other short of the plane through
/// that one's; with no corner of either moving towards the other by more than fraction x (d - m),
/// the slab between the two planes keeps (1 - 2 fraction) d + 2 fraction m, however far they move
/// along them. The normal that rounds off the true one by e carries a step s along it by e |s| more
/// than it says: the slack.
SIM_INLINE SlideHalf slideConstraint(vec3 x0, vec3 x1, vec3 x2, vec3 x3, NearestPoints c, bool edge, float radius,
                                     float fraction, uint k) {
  SlideHalf r;
  r.h = vec4(0.0f, 0.0f, 0.0f, -1.0f);
  r.slack = 0.0f;
  float margin = SIM_CONTACT_MARGIN * radius;
  if (!(c.d2 < radius * radius) || !(c.d2 > 0.0f)) return r;
  vec3 sep = x0 * c.w.x + x1 * c.w.y + x2 * c.w.z + x3 * c.w.w;
  vec3 big = max(max(abs(x0), abs(x1)), max(abs(x2), abs(x3)));
  float len = simSqrt(c.d2);
  r.h = vec4(sep * simDiv(k == 0u || (edge && k == 1u) ? 1.0f : -1.0f, len), fraction * max(len - margin, 0.0f));
  r.slack = SIM_CONTACT_SLACK * simDiv(max(big.x, max(big.y, big.z)) + 1.0f, len);
  return r;
}

/// How far `step` goes along the half-space's normal, less its slack: against it when negative.
SIM_INLINE float slideAgainst(SlideHalf c, vec3 step) {
  return dot3(vec3(c.h), step) - c.slack * simSqrt(dot3(step, step));
}

/// The move along the half-space's normal that takes out what `step` goes against it beyond h.w;
/// zero when the step keeps it.
SIM_INLINE vec3 slideExcess(SlideHalf c, vec3 step) {
  float a = slideAgainst(c, step);
  return c.h.w >= 0.0f && a < -c.h.w ? vec3(c.h) * (-c.h.w - a) : vec3(0.0f);
}

/// The largest share in [0, 1] of `step` that keeps the half-space (slideAgainst scales with the
/// step, and the zero step keeps it).
SIM_INLINE float slideShare(SlideHalf c, vec3 step) {
  float a = slideAgainst(c, step);
  return c.h.w >= 0.0f && a < -c.h.w ? simDiv(c.h.w, -a) : 1.0f;
}

/// True when particle k of a pair (`edge`: two edges, particles 0-1 and 2-3; else particle 0 and
/// a triangle) lies on the other primitive from particle j.
SIM_INLINE bool contactOpposite(uint j, uint k, bool edge) {
  return edge ? ((j < 2u) != (k < 2u)) : ((j == 0u) != (k == 0u));
}

/// What particle k of pair c is passed of the excess `e` taken out of the step of a particle on the
/// other primitive (slideExcess): SIM_CONTACT_PASS_FRACTION of it, the other way, weighed by k's part
/// in the pair's nearest point (the weights of a primitive sum to one). A particle's passed steps
/// are summed in fixed point and their mean added to its step (passedPosition) before its own
/// half-spaces cut it, so every step is still cut and no pair can close: contact passes momentum
/// on instead of only taking it out.
SIM_INLINE vec3 contactPassed(vec3 e, NearestPoints c, uint k) {
  float wk = k == 0u ? c.w.x : (k == 1u ? c.w.y : (k == 2u ? c.w.z : c.w.w));
  return e * (-SIM_CONTACT_PASS_FRACTION * abs(wk));
}

/// Where a particle at p goes with its passed step (the mean of contactPassed): never below the
/// floor at floor_y when it was on or above it.
SIM_INLINE vec3 passedPosition(vec4 p, vec3 passed, float floor_y) {
  vec3 x = vec3(p) + passed;
  x.y = max(x.y, min(p.y, floor_y));
  return x;
}

/// A particle's state moved by its passed step (passedPosition), its previous position with it: the
/// step moves it without speeding it up, as the push does. (Passed as a velocity, a tenth of the
/// excess kept four particles of a fold of a crumple on the floor shaking in turn at 1.4 units/s,
/// each substep's pass answering the last.)
SIM_INLINE VerletState passedState(VerletState st, vec3 passed, float floor_y) {
  vec3 x = passedPosition(st.position, passed, floor_y);
  vec3 d = x - vec3(st.position);
  VerletState r;
  r.position = vec4(x, st.position.w);
  r.previous = vec4(vec3(st.previous) + d, st.previous.w);
  return r;
}

/// Where a particle's step less the frame goes before its bound (slideStep): p itself when no
/// half-space cuts it (`share` 1, no `excess`), else its excess (the mean of slideExcess over its
/// pairs) taken out and the rest cut to `share` (the least slideShare of that over its pairs).
SIM_INLINE vec3 slideTarget(vec3 p, vec3 from, vec3 excess, float share) {
  return share < 1.0f || dot3(excess, excess) > 0.0f ? from + ((p - from) + excess) * share : p;
}

/// A particle's substep with contact (st: where it ends after the floor and its previous position;
/// x0: where it started; push: contactPushWithin; frame: contactFrame; excess and share: what its
/// pairs' half-spaces take out of its step and leave of it, slideTarget): the step less the frame
/// cut to them, then to `bound`, then pushed (contactStepTo).
SIM_INLINE VerletState slideStep(VerletState st, vec3 x0, vec3 push, vec3 excess, float share, float bound,
                                 vec3 frame) {
  return contactStepTo(st, slideTarget(vec3(st.position), x0 + frame, excess, share), x0, push, bound, frame);
}

/// The largest t in [0, 1] for which the step s + t d stays within the ball of radius `ball` (s
/// within it); 0 for no move.
SIM_INLINE float ballRoom(vec3 s, vec3 d, float ball) {
  float dd = dot3(d, d), sd = dot3(s, d);
  if (!(dd > 0.0f)) return 0.0f;
  float disc = sd * sd - dd * (dot3(s, s) - ball * ball);
  if (!(disc >= 0.0f)) return 0.0f;
  return max(min(1.0f, simDiv(simSqrt(disc) - sd, dd)), 0.0f);
}

/// A t in [0, 1] for which the step s + t d keeps half-space c (slideAgainst of it at least -h.w)
/// when s does (`s_len`, `d_len`: their lengths): slideAgainst is at least A + t B with
/// |s + t d| <= |s| + t |d|, linear in t. A step that already meets it (A <= 0, up to rounding) may
/// not go further against it.
SIM_INLINE float halfSpaceRoom(SlideHalf c, vec3 s, float s_len, vec3 d, float d_len) {
  float a = dot3(vec3(c.h), s) - c.slack * s_len + c.h.w, b = dot3(vec3(c.h), d) - c.slack * d_len;
  return b < 0.0f ? min(1.0f, simDiv(max(a, 0.0f), -b)) : 1.0f;
}

/// Six times the signed volume of the tetrahedron a, b, c, d: positive when d lies on the side of
/// the triangle a, b, c that (b - a) x (c - a) points to.
SIM_INLINE float orient3(vec3 a, vec3 b, vec3 c, vec3 d) { return dot3(cross3(b - a, c - a), d - a); }

/// True when the segment p-q passes through the triangle a, b, c: its ends strictly on either side
/// of the triangle's plane and its line strictly inside the triangle's three edges.
SIM_INLINE bool segmentCrossesTriangle(vec3 p, vec3 q, vec3 a, vec3 b, vec3 c) {
  float sp = orient3(a, b, c, p), sq = orient3(a, b, c, q);
  if (!((sp > 0.0f && sq < 0.0f) || (sp < 0.0f && sq > 0.0f))) return false;
  float e0 = orient3(p, q, a, b), e1 = orient3(p, q, b, c), e2 = orient3(p, q, c, a);
  return (e0 > 0.0f && e1 > 0.0f && e2 > 0.0f) || (e0 < 0.0f && e1 < 0.0f && e2 < 0.0f);
}

/// True when the triangles a0, a1, a2 and b0, b1, b2 cross: an edge of one passes through the
/// other (two triangles that cut each other do so along a segment whose ends are such crossings).
/// In floats, the same bits on every device: it says which triangles untangle (`free` particles),
/// not whether the sheet is whole; the outside judge (core/intersections.h) is exact.
SIM_INLINE bool trianglesCross(vec3 a0, vec3 a1, vec3 a2, vec3 b0, vec3 b1, vec3 b2) {
  return segmentCrossesTriangle(a0, a1, b0, b1, b2) || segmentCrossesTriangle(a1, a2, b0, b1, b2) ||
         segmentCrossesTriangle(a2, a0, b0, b1, b2) || segmentCrossesTriangle(b0, b1, a0, a1, a2) ||
         segmentCrossesTriangle(b1, b2, a0, a1, a2) || segmentCrossesTriangle(b2, b0, a0, a1, a2);
}

/// Edge p-q (corners kp, kq of a crossing pair's six: 0-2 the first triangle's, 3-5 the second's)
/// against triangle t0, t1, t2 (corners kt to kt + 2): when the edge passes through it, corner k's
/// share of drawing the edge's end nearer the triangle's plane back through it, to `gap` beyond:
/// the end moves half of that along the plane's normal, the triangle's corners the other half the
/// other way. Zero for every other corner.
SIM_INLINE vec3 untangleEdge(vec3 p, vec3 q, vec3 t0, vec3 t1, vec3 t2, float gap, uint kp, uint kq, uint kt, uint k) {
  bool at_edge = k == kp || k == kq, at_triangle = k >= kt && k < kt + 3u;
  if (!(at_edge || at_triangle) || !segmentCrossesTriangle(p, q, t0, t1, t2)) return vec3(0.0f);
  vec3 n = cross3(t1 - t0, t2 - t0);
  float n2 = dot3(n, n), sp = dot3(n, p - t0), sq = dot3(n, q - t0);
  // The nearer end, by its signed distance times |n|
  bool p_nearer = abs(sp) <= abs(sq);
  float side = p_nearer ? sp : sq;
  if ((at_edge && k != (p_nearer ? kp : kq)) || !(n2 > 0.0f)) return vec3(0.0f);
  float len = simSqrt(n2), half_way = 0.5f * (simDiv(abs(side), len) + gap);
  vec3 along = n * simDiv(side > 0.0f ? half_way : -half_way, len); // from the plane towards the end
  return at_edge ? -along : along;
}

/// Corner k's push (0-2: a's, 3-5: b's) that untangles two crossing triangles: every edge of one
/// that passes through the other is drawn back through it at its nearer end (untangleEdge), to
/// `gap` beyond. Where the sheet crosses itself (contact turned on in a tangled sheet), the
/// particles of crossing triangles are free of their bounds, and these pushes (with the contact's,
/// cut to contactPushWithin) part the layers again.
SIM_INLINE vec3 untanglePush(vec3 a0, vec3 a1, vec3 a2, vec3 b0, vec3 b1, vec3 b2, float gap, uint k) {
  return untangleEdge(a0, a1, b0, b1, b2, gap, 0u, 1u, 3u, k) + untangleEdge(a1, a2, b0, b1, b2, gap, 1u, 2u, 3u, k) +
         untangleEdge(a2, a0, b0, b1, b2, gap, 2u, 0u, 3u, k) + untangleEdge(b0, b1, a0, a1, a2, gap, 3u, 4u, 0u, k) +
         untangleEdge(b1, b2, a0, a1, a2, gap, 4u, 5u, 0u, k) + untangleEdge(b2, b0, a0, a1, a2, gap, 5u, 3u, 0u, k);
}

/// A pair's push on one particle in fixed point (`scale`: SimUniforms::contact.fixed_units units per unit of
/// length), clamped to +-SIM_CONTACT_FIXED_MAX: integers sum to the same bits in any order, so a
/// particle's pushes need no fixed order (atomic adds on the GPU).
SIM_INLINE ivec3 contactFixed(vec3 push, float scale) {
  return ivec3(roundEven(clamp(push * scale, vec3(-SIM_CONTACT_FIXED_MAX), vec3(SIM_CONTACT_FIXED_MAX))));
}

/// The average of a particle's pushes from their fixed-point sum (xyz) and count (w).
SIM_INLINE vec3 contactAverage(ivec4 sum, float scale) {
  return sum.w > 0 ? vec3(sum.x, sum.y, sum.z) * simDiv(1.0f, scale * float(sum.w)) : vec3(0.0f);
}

/// True when a triangle is looked at for crossing the sheet this substep: every triangle when the
/// check is `all`, else those that hold a particle let free in the last substep (`was_free`). Only
/// unbounded motion can carry a triangle through another, and every particle that moves is bounded
/// (contactBounded) but those of triangles that already cross.
SIM_INLINE bool crossingChecked(bool all, bool was_free) { return all || was_free; }

#endif
