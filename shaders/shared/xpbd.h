// Per-particle and per-constraint maths, called by the GLSL main()s and the C++ reference alike.
// Functions take values and return values (no inout) so that one body compiles as both.
#ifndef SIM_XPBD_H
#define SIM_XPBD_H
#include "exact_math.h"
#include "sim_passes.h"
#include "sim_types.h"

/// Position and previous position of one particle.
struct VerletState {
  vec4 position;
  vec4 previous;
};

/// Position corrections of the two ends of a constraint.
struct PairDelta {
  vec3 da;
  vec3 db;
};

/// Substeps a tick runs: as many as asked, at most SIM_MAX_SUBSTEPS (the per-substep inputs).
SIM_INLINE uint substepCount(uint substeps) { return min(substeps, uint(SIM_MAX_SUBSTEPS)); }

/// True when constraints may tear: a tear factor of 0 (or less) disables tearing.
SIM_INLINE bool tearingOn(float tear_factor) { return tear_factor > 0.0f; }

/// A particle at its start: the rest position, inverse mass 0 at a pin point, else 1.
SIM_INLINE vec4 startPosition(vec4 rest) { return vec4(vec3(rest), rest.w > 0.5f ? 0.0f : 1.0f); }

/// Inverse mass of a particle this substep: 0 when pinned (and pins are on) or held by a grab.
SIM_INLINE float inverseMass(vec4 rest, bool held, uint flags) {
  bool pinned = (flags & SIM_FLAG_PINS) != 0u && rest.w > 0.5f;
  return (pinned || held) ? 0.0f : 1.0f;
}

/// External acceleration of a free particle: gravity plus wind (uniform and twisting across u).
SIM_INLINE vec3 externalAccel(float gravity, vec4 wind, vec4 wind_twist, float u) {
  return vec3(0.0f, -gravity, 0.0f) + vec3(wind) + vec3(wind_twist) * (u - 0.5f);
}

/// Damped Verlet step: x' = x + (x - x_prev) * damping + a * dt^2; x_prev' = x.
SIM_INLINE VerletState verletStep(vec4 pos, vec4 prev, vec3 accel, float damping, float dt2, float w) {
  VerletState s;
  vec3 p = vec3(pos);
  if (w > 0.0f) {
    vec3 v = (p - vec3(prev)) * damping;
    s.position = vec4(p + v + accel * dt2, w);
  } else {
    s.position = vec4(p, w);
  }
  s.previous = vec4(p, w);
  return s;
}

/// Where in the fist the hand draws particle i, relative to its centre, per unit of fist radius:
/// each component in [-1/4, 1/4), from a hash of i. The fingers are not a perfect sphere: a sheet
/// lying flat through the centre buckles out of its plane instead of being squeezed within it.
SIM_INLINE vec3 handFinger(uint i) {
  uint h = i * 0x9E3779B9u;
  h ^= h >> 16u;
  h *= 0x7FEB352Du;
  h ^= h >> 15u;
  vec3 k = vec3(float(h & 1023u), float((h >> 10u) & 1023u), float((h >> 20u) & 1023u));
  return k * 0.00048828125f - vec3(0.25f); // k / 2048 - 1/4, exact
}

/// The hand closing around the grab (hand.reach > 0, see SimUniforms::hand) on free particle i
/// that the Verlet step took from `previous` to `position`: within the hand's reach of its centre
/// (the grab target) the grip takes hand.grip of the particle's velocity relative to the hand's
/// motion, then the particle is drawn hand.draw of its way toward the fist (a ball of radius
/// hand.fist around the centre, moved by handFinger(i) x hand.fist). The fist rests on the floor:
/// its centre is never lower than motion.lowest (the floor plus the fist's radius), so a hand
/// closing or pressing down near the floor forms its ball above it, with the grab at the ball's
/// foot, instead of drawing the sheet into the floor. Returns the particle's new position.
SIM_INLINE vec4 handPull(vec4 position, vec4 previous, uint i, vec3 centre, HandKeys hand, HandMotion motion) {
  if (!(hand.reach > 0.0f) || !(position.w > 0.0f)) return position; // an open hand: nothing to do
  vec3 p = vec3(position);
  vec3 d = p - centre;
  if (dot3(d, d) < hand.reach * hand.reach) {
    p = p - (p - vec3(previous) - motion.per_substep) * hand.grip;
    vec3 fist = vec3(centre.x, max(centre.y, motion.lowest), centre.z);
    d = p - (fist + handFinger(i) * hand.fist);
    float dist = simSqrt(dot3(d, d));
    if (dist > hand.fist) p = p - d * (simDiv(dist - hand.fist, dist) * hand.draw);
  }
  return vec4(p, position.w);
}

/// Whether the grab places particle i this substep (held, or let go as a toss), rather than the
/// Verlet step and the hand's pull moving it.
SIM_INLINE bool placedByGrab(bool is_grabbed, vec4 grab_target) { return is_grabbed && grab_target.w > 0.5f; }

/// A particle's integration at a substep with the hand open. The grabbed particle (is_grabbed)
/// follows grab_target when grab_target.w is 1 (held: infinite mass, previous position grab_prev)
/// or is let go with the velocity grab_target - grab_prev when grab_target.w is 2 (a toss);
/// otherwise damped Verlet.
SIM_INLINE VerletState integrateOpenHand(vec4 pos, vec4 prev, vec4 rest, float u, bool is_grabbed, vec4 grab_target,
                                         vec4 grab_prev, uint flags, float gravity, vec4 wind, vec4 wind_twist,
                                         float damping, float dt2) {
  bool placed = placedByGrab(is_grabbed, grab_target);
  bool held = placed && grab_target.w < 1.5f;
  float w = inverseMass(rest, held, flags);
  VerletState s;
  if (placed) {
    s.position = vec4(vec3(grab_target), w);
    s.previous = vec4(vec3(grab_prev), w);
  } else {
    s = verletStep(pos, prev, externalAccel(gravity, wind, wind_twist, u), damping, dt2, w);
  }
  return s;
}

/// Particle i's integration at a substep: integrateOpenHand, then, while a grab is held, the hand's
/// pull on every particle it did not place (handPull, which moves nothing while the hand is open).
SIM_INLINE VerletState integrateParticle(uint i, vec4 pos, vec4 prev, vec4 rest, float u, bool is_grabbed,
                                         vec4 grab_target, vec4 grab_prev, HandKeys hand, HandMotion hand_motion,
                                         uint flags, float gravity, vec4 wind, vec4 wind_twist, float damping,
                                         float dt2) {
  VerletState s = integrateOpenHand(pos, prev, rest, u, is_grabbed, grab_target, grab_prev, flags, gravity, wind,
                                    wind_twist, damping, dt2);
  if (!placedByGrab(is_grabbed, grab_target))
    s.position = handPull(s.position, s.previous, i, vec3(grab_target), hand, hand_motion);
  return s;
}

/// Whether a constraint (its packed kind and id) projects in iteration `iteration` of a substep: a
/// hinge in the first only, so that the bending is one XPBD step per substep whatever the
/// iteration count (its stiffness is its compliance alone) and the distance constraints, projected
/// in every iteration, have the last word on the stretch; every other constraint in each. Hinges
/// have colours of their own, so a whole colour projects or not: every path asks this of a
/// colour's first constraint and skips the colour.
SIM_INLINE bool projectsInIteration(uint kind_id, uint iteration) {
  return iteration == 0u || (kind_id & SIM_KIND_MASK) != SIM_KIND_HINGE;
}

/// Projects one distance constraint; corrections are weighted by inverse mass (pos.w).
SIM_INLINE PairDelta solveDistance(vec4 pa, vec4 pb, float rest, float stiffness) {
  PairDelta r;
  r.da = vec3(0.0f);
  r.db = vec3(0.0f);
  float wsum = pa.w + pb.w;
  vec3 d = vec3(pb) - vec3(pa);
  float len = simSqrt(dot3(d, d));
  if (wsum > 0.0f && len > 1e-9f) {
    float s = simDiv(stiffness * (len - rest), len * wsum);
    r.da = d * (s * pa.w);
    r.db = d * (-s * pb.w);
  }
  return r;
}

/// Ground contact: clamp to the floor, reflect normal velocity with restitution, apply friction.
SIM_INLINE VerletState floorContact(vec4 pos, vec4 prev, float floor_y, float restitution, float friction) {
  VerletState s;
  s.position = pos;
  s.previous = prev;
  if (pos.y < floor_y) {
    float vy = min(pos.y - prev.y, 0.0f);
    float keep = 1.0f - friction;
    s.position.y = floor_y;
    s.previous.y = floor_y + vy * restitution;
    s.previous.x = pos.x - (pos.x - prev.x) * keep;
    s.previous.z = pos.z - (pos.z - prev.z) * keep;
  }
  return s;
}

/// A particle's position after its collision delta (the repel pass): moved when collision is on and
/// the particle is free. The repulsion comes before the projection, so that the distance constraints
/// have the last word on what it stretches.
SIM_INLINE vec4 repelParticle(vec4 pos, vec3 collision_delta, uint flags) {
  if ((flags & SIM_FLAG_COLLISION) != 0u && pos.w > 0.0f) pos += vec4(collision_delta, 0.0f);
  return pos;
}

/// True when a constraint of this kind is stretched beyond tear_factor x rest.
SIM_INLINE bool shouldTear(vec4 pa, vec4 pb, float rest, uint kind, float tear_factor, uint tear_kinds) {
  bool tearable = tearingOn(tear_factor) && (tear_kinds & (1u << kind)) != 0u;
  vec3 d = vec3(pb) - vec3(pa);
  return tearable && simSqrt(dot3(d, d)) > rest * tear_factor;
}

/// The two triangles (original ids: two per quad, row by row, see buildSheet) a shear or
/// tri-bend constraint from particle a to particle b of a `cols`-wide grid stands on: for a shear
/// the two halves of the quad it crosses, for a tri-bend the two triangles on either side of the
/// structural edge it bends across. (SIM_NONE, SIM_NONE) for the other kinds.
SIM_INLINE uvec2 supportTriangles(uint a, uint b, uint kind, uint cols) {
  uint ax = a % cols, ay = a / cols, bx = b % cols, by = b / cols;
  uint x = min(ax, bx), y = min(ay, by), dx = max(ax, bx) - x, dy = max(ay, by) - y;
  uint quads = cols - 1u;
  if (kind == SIM_KIND_SHEAR) return uvec2(2u * (y * quads + x), 2u * (y * quads + x) + 1u);
  if (kind != SIM_KIND_TRIBEND) return uvec2(SIM_NONE, SIM_NONE);
  // Across a horizontal edge (x, y + 1)-(x + 1, y + 1): the quad above's first triangle, the
  // quad below's second; across a vertical edge (x + 1, y)-(x + 1, y + 1): the left quad's second,
  // the right quad's first.
  if (dx == 1u) return uvec2(2u * (y * quads + x), 2u * ((y + 1u) * quads + x) + 1u);
  return dy == 1u ? uvec2(2u * (y * quads + x) + 1u, 2u * (y * quads + x + 1u)) : uvec2(SIM_NONE, SIM_NONE);
}

/// True when a shear, tri-bend or hinge constraint from particle a to particle b (a < b) of a
/// `cols`-wide grid has lost what it stands on (gone0, gone1: its support triangles lost an edge).
/// A shear along the diagonal both halves of its quad share (top-left to bottom-right) goes once
/// both are gone; the other diagonal, which crosses both halves, and a tri-bend or a hinge, which
/// cross both triangles of their edge, go once either is. No constraint then spans a triangle the sheet has
/// lost, so torn pieces come apart; a fold tears nothing.
SIM_INLINE bool unsupported(uint a, uint b, uint kind, uint cols, bool gone0, bool gone1) {
  bool shared_diagonal = kind == SIM_KIND_SHEAR && b == a + cols + 1u;
  if (shared_diagonal) return gone0 && gone1;
  return (kind == SIM_KIND_SHEAR || kind == SIM_KIND_TRIBEND || kind == SIM_KIND_HINGE) && (gone0 || gone1);
}

/// The triangles (original ids; SIM_NONE where the sheet ends) that hold the structural edge from
/// particle a to its grid neighbour b = a + 1 or a + cols: a row edge is the top edge of the second
/// triangle of the quad below it and the bottom edge of the first of the quad above; a column edge
/// the left edge of the first triangle of the quad to its right and the right edge of the second of
/// the quad to its left.
SIM_INLINE uvec2 edgeTriangles(uint a, uint b, uint cols, uint rows) {
  uint x = a % cols, y = a / cols, quads = cols - 1u;
  // a row edge: b the next particle of a's row (in a sheet one particle wide, b == a + 1 is a's
  // column neighbour, whose edge no triangle holds)
  if (b == a + 1u && x + 1u < cols)
    return uvec2(y + 1u < rows ? 2u * (y * quads + x) + 1u : SIM_NONE, y > 0u ? 2u * ((y - 1u) * quads + x) : SIM_NONE);
  return uvec2(x + 1u < cols ? 2u * (y * quads + x) : SIM_NONE, x > 0u ? 2u * (y * quads + x - 1u) + 1u : SIM_NONE);
}

#include "limit.h"

/// Hinges of a cols x rows grid (SIM_KIND_HINGE, numbered as gridHinge takes them): one across each
/// interior row edge, each interior column edge and the diagonal of each quad.
SIM_INLINE uint hingeCount(uint cols, uint rows) {
  if (cols < 2u || rows < 2u) return 0u;
  return (cols - 1u) * (rows - 2u) + (cols - 2u) * (rows - 1u) + (cols - 1u) * (rows - 1u);
}

/// Hinge k (< hingeCount) of a cols x rows grid: x and y the ends of its edge, z and w the corners
/// opposite it, so that (x, y, z) and (y, x, w) are its two triangles counter-clockwise from +Z (as
/// gridTriangle gives them). The hinges across the row edges (i, j)-(i + 1, j) of rows 1 to
/// rows - 2 come first, row by row; then those across the column edges (i, j)-(i, j + 1) of
/// columns 1 to cols - 2; then the diagonal top-left to bottom-right of each quad.
SIM_INLINE uvec4 gridHinge(uint k, uint cols, uint rows) {
  uint row_hinges = (cols - 1u) * (rows - 2u), col_hinges = (cols - 2u) * (rows - 1u);
  if (k < row_hinges) {
    uint p = (k / (cols - 1u) + 1u) * cols + k % (cols - 1u);
    return uvec4(p, p + 1u, p - cols, p + cols + 1u);
  }
  k -= row_hinges;
  if (k < col_hinges) {
    uint p = (k / (cols - 2u)) * cols + k % (cols - 2u) + 1u;
    return uvec4(p, p + cols, p + cols + 1u, p - 1u);
  }
  k -= col_hinges;
  uint tl = (k / (cols - 1u)) * cols + k % (cols - 1u);
  return uvec4(tl + cols + 1u, tl, tl + cols, tl + 1u);
}

/// The first hinge of a cols x rows grid (cols, rows >= 2) that is a quad's diagonal: those after
/// the row and column edges' (gridHinge).
SIM_INLINE uint firstDiagonalHinge(uint cols, uint rows) {
  return (cols - 1u) * (rows - 2u) + (cols - 2u) * (rows - 1u);
}

/// True when hinge k of a cols x rows grid is a quad's diagonal (its edge is sqrt 2 x spacing long:
/// the same rigidity takes half the compliance there).
SIM_INLINE bool hingeIsDiagonal(uint k, uint cols, uint rows) { return k >= firstDiagonalHinge(cols, rows); }

/// The two triangles (original ids) of hinge k of a cols x rows grid: the one with corner z of
/// gridHinge, then the one with corner w.
SIM_INLINE uvec2 hingeTriangles(uint k, uint cols, uint rows) {
  uint quads = cols - 1u, row_hinges = quads * (rows - 2u), col_hinges = (cols - 2u) * (rows - 1u);
  if (k < row_hinges) {
    uint q = (k / quads + 1u) * quads + k % quads; // the quad below the edge
    return uvec2(2u * (q - quads), 2u * q + 1u);
  }
  k -= row_hinges;
  if (k < col_hinges) {
    uint q = (k / (cols - 2u)) * quads + k % (cols - 2u) + 1u; // the quad right of the edge
    return uvec2(2u * q, 2u * (q - 1u) + 1u);
  }
  k -= col_hinges;
  return uvec2(2u * k, 2u * k + 1u);
}

/// The signed angle of a hinge and its gradient (Bergou et al., Discrete Shells).
struct HingeAngle {
  float angle; // radians in (-pi, pi]: 0 flat, positive when either corner moves along its triangle's normal
  bool valid;  // false for a degenerate hinge (an edge or a triangle of no size): no angle
  vec3 gu, gv, ga, gb;
};

/// The angle of the hinge with edge pu-pv and opposite corners pa and pb (gridHinge's order): from
/// the normals na of (pu, pv, pa) and nb of (pv, pu, pb), atan2 of (nb x na) . e and (na . nb) |e|.
/// With `gradient`, the gradient: a corner moves the angle by its normal over its height above the
/// edge, and the ends of the edge take the rest by the lever rule, so the four sum to zero.
SIM_INLINE HingeAngle hingeAngle(vec3 pu, vec3 pv, vec3 pa, vec3 pb, bool gradient) {
  HingeAngle h;
  h.angle = 0.0f;
  h.valid = false;
  h.gu = vec3(0.0f);
  h.gv = vec3(0.0f);
  h.ga = vec3(0.0f);
  h.gb = vec3(0.0f);
  vec3 e = pv - pu;
  vec3 na = cross3(e, pa - pu), nb = cross3(pu - pv, pb - pv);
  float e2 = dot3(e, e), na2 = dot3(na, na), nb2 = dot3(nb, nb);
  // A triangle whose height is under 1e-4 of its edge has no normal to speak of
  float tiny = 1e-8f * e2 * e2;
  if (!(e2 > 1e-30f) || !(na2 > tiny) || !(nb2 > tiny) || !(na2 < 1e30f) || !(nb2 < 1e30f)) return h;
  float el = simSqrt(e2);
  h.angle = simAtan2(dot3(cross3(nb, na), e), dot3(na, nb) * el);
  h.valid = true;
  if (!gradient) return h;
  h.ga = na * simDiv(el, na2);
  h.gb = nb * simDiv(el, nb2);
  float inv_e2 = simDiv(1.0f, e2);
  float sa = dot3(pa - pu, e) * inv_e2, sb = dot3(pb - pu, e) * inv_e2;
  h.gu = -(h.ga * (1.0f - sa) + h.gb * (1.0f - sb));
  h.gv = -(h.ga * sa + h.gb * sb);
  return h;
}

/// Corrections of the four corners of a hinge and its new XPBD multiplier.
struct HingeDelta {
  vec3 du, dv, da, db;
  float lambda;
};

/// One XPBD step of a hinge (corners pu, pv, pa, pb; w the inverse mass) toward its rest angle:
/// with compliance over dt^2 `alpha` and the multiplier so far `lambda`,
/// dlambda = (-C - alpha lambda) / (sum w |grad C|^2 + alpha), C = wrap(angle - rest).
SIM_INLINE HingeDelta solveHinge(vec4 pu, vec4 pv, vec4 pa, vec4 pb, float rest, float alpha, float lambda) {
  HingeDelta r;
  r.du = vec3(0.0f);
  r.dv = vec3(0.0f);
  r.da = vec3(0.0f);
  r.db = vec3(0.0f);
  r.lambda = lambda;
  HingeAngle h = hingeAngle(vec3(pu), vec3(pv), vec3(pa), vec3(pb), true);
  if (!h.valid) return r;
  float c = wrapAngle(h.angle - rest);
  float denom =
      ((pu.w * dot3(h.gu, h.gu) + pv.w * dot3(h.gv, h.gv)) + pa.w * dot3(h.ga, h.ga)) + pb.w * dot3(h.gb, h.gb) + alpha;
  if (!(denom > 0.0f)) return r;
  float dl = simDiv(-c - alpha * lambda, denom);
  r.du = h.gu * (dl * pu.w);
  r.dv = h.gv * (dl * pv.w);
  r.da = h.ga * (dl * pa.w);
  r.db = h.gb * (dl * pb.w);
  r.lambda = lambda + dl;
  return r;
}

/// The crease of a hinge after a substep's projection (once per substep, so it does not depend on
/// the iteration count): a return map. With d = wrap(angle - rest) and the yield y = yield0 +
/// state.y, a hinge bent |d| - y past its yield moves its rest angle that far toward its angle over
/// (1 + hardening), and the hardening raises its yield by as much. yield0 = 0: elastic.
SIM_INLINE HingeState creaseReturn(HingeState st, float angle, float yield0, float hardening) {
  float d = wrapAngle(angle - st.x);
  float over = abs(d) - (yield0 + st.y);
  if (yield0 > 0.0f && over > 0.0f) {
    float step = simDiv(over, 1.0f + hardening);
    st.x = wrapAngle(st.x + (d < 0.0f ? -step : step));
    st.y = st.y + hardening * step;
  }
  return st;
}

/// The particles of triangle t (original id: two per quad, row by row, as buildSheet makes them:
/// top-left, bottom-left, bottom-right, then top-left, bottom-right, top-right) of a cols-wide grid.
SIM_INLINE uvec3 gridTriangle(uint t, uint cols) {
  uint quad = t / 2u, quads = cols - 1u;
  uint tl = (quad / quads) * cols + quad % quads, bl = tl + cols;
  return (t & 1u) == 0u ? uvec3(tl, bl, bl + 1u) : uvec3(tl, bl + 1u, tl + 1u);
}

/// The k-th (k < 6) triangle (original id) with particle i of a cols x rows grid as a corner, or
/// SIM_NONE: both halves of the quad below-right, one of the quads left and above, both of the
/// quad above-left.
SIM_INLINE uint particleTriangle(uint i, uint k, uint cols, uint rows) {
  uint x = i % cols, y = i / cols, quads = cols - 1u;
  bool right = x + 1u < cols, below = y + 1u < rows, left = x > 0u, above = y > 0u;
  if (k < 2u) return right && below ? 2u * (y * quads + x) + k : SIM_NONE;
  if (k == 2u) return left && below ? 2u * (y * quads + x - 1u) + 1u : SIM_NONE;
  if (k == 3u) return right && above ? 2u * ((y - 1u) * quads + x) : SIM_NONE;
  return left && above ? 2u * ((y - 1u) * quads + x - 1u) + (k - 4u) : SIM_NONE;
}

/// The air on a triangle now at pa, pb, pc and a substep ago at qa, qb, qc, per unit mass of its
/// paper: the pressure of quadratic drag along its normal (which lifts a tilted sheet as it
/// slows it) and skin friction along its plane, both growing with its area (AirKeys).
SIM_INLINE vec3 airOnTriangle(vec3 pa, vec3 pb, vec3 pc, vec3 qa, vec3 qb, vec3 qc, AirKeys air) {
  vec3 v = ((pa - qa) + (pb - qb) + (pc - qc)) * air.third_over_dt;
  vec3 n = cross3(pb - pa, pc - pa);
  float n2 = dot3(n, n), v2 = dot3(v, v);
  if (!(n2 > 1e-30f) || !(v2 > 0.0f)) return vec3(0.0f);
  // |n| is twice the area; vn the velocity along the normal, vt the rest
  float k = simSqrt(v2) * simSqrt(n2);
  vec3 vn = n * simDiv(dot3(v, n), n2);
  vec3 vt = v - vn;
  return vn * (-air.pressure * k) + vt * (-air.friction * k);
}

/// The air on a particle: the mean over the live triangles around it (sum of airOnTriangle over
/// `count` of them), each triangle's paper sharing its mass equally among its corners.
SIM_INLINE vec3 meanAir(vec3 sum, uint count) {
  if (count == 0u) return vec3(0.0f);
  float c = float(count);
  return vec3(simDiv(sum.x, c), simDiv(sum.y, c), simDiv(sum.z, c));
}

/// The Verlet damping of substep s (SimUniforms::damping and verlet): the first substep's rescales
/// the velocity the last tick left to this tick's substep as well.
SIM_INLINE float substepDamping(float damping, VerletKeys verlet, uint s) {
  return s == 0u ? verlet.first_damping : damping;
}

/// The wind a particle integrates with: the substep's, plus the air on it (from the air pass) when
/// SIM_FLAG_AIR is set.
SIM_INLINE vec4 windWithAir(vec4 wind, vec4 air_on_particle, uint flags) {
  return (flags & SIM_FLAG_AIR) != 0u ? wind + air_on_particle : wind;
}

/// Smooth normal of grid particle (i, j) from central differences of its neighbours.
SIM_INLINE vec3 gridNormal(vec3 left, vec3 right, vec3 up, vec3 down) {
  vec3 n = cross3(right - left, up - down);
  float l2 = dot3(n, n);
  if (!(l2 > 1e-20f)) return vec3(0.0f, 0.0f, 1.0f);
  float len = simSqrt(l2);
  return vec3(simDiv(n.x, len), simDiv(n.y, len), simDiv(n.z, len));
}

/// Squared distance from point p to the ray o + t d (|d| = 1), and t; t < 0 gives a huge distance.
SIM_INLINE vec2 rayPointDistance2(vec3 o, vec3 d, vec3 p) {
  float t = dot3(p - o, d);
  vec3 q = o + d * t - p;
  return vec2(t < 0.0f ? 3.0e38f : dot3(q, q), t);
}

#include "collision.h"
#include "contact.h"

#endif
