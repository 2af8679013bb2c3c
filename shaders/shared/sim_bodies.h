// Per-element bodies of the simulation's passes that the CPU reference runs as they are (the
// projection, the air, the tear marks): the
// shaders' main()s and the fused tick call them (sim_elements.glsl includes this file after the
// buffers), and so does CpuSolver (sheet_elements.h beside it includes it inside a struct whose
// members bear the buffers' names). They read the sheet by those names: u (SimUniforms), prev,
// torn, tri_edges, hinges, counters, and the positions through SIM_POSITION(j); atomicAdd and
// atomicExchange are GLSL's (C++: shaderio.h).
#ifndef SIM_BODIES_H
#define SIM_BODIES_H

// Position of particle j as the bodies read and write it (the fused tick: shared memory)
#ifndef SIM_POSITION
#define SIM_POSITION(j) pos[j]
#endif

/// Projects hinge k (SIM_KIND_HINGE), once per substep (projectsInIteration): one XPBD step of its
/// four corners toward its rest angle (solveHinge) from a zero multiplier, which no later step
/// reads, so it is not kept.
SIM_INLINE void projectHinge(uint k) {
  uvec4 q = gridHinge(k, u.cols, u.rows);
  vec4 pu = SIM_POSITION(q.x), pv = SIM_POSITION(q.y), pa = SIM_POSITION(q.z), pb = SIM_POSITION(q.w);
  CreaseKeys crease = u.crease; // uniform vectors whole (SpirvRules: a fleet's kernels read them by address)
  float alpha = hingeIsDiagonal(k, u.cols, u.rows) ? 0.5f * crease.compliance : crease.compliance;
  HingeDelta d = solveHinge(pu, pv, pa, pb, hinges[k].x, alpha, 0.0f);
  SIM_POSITION(q.x) = pu + vec4(d.du, 0.0f);
  SIM_POSITION(q.y) = pv + vec4(d.dv, 0.0f);
  SIM_POSITION(q.z) = pa + vec4(d.da, 0.0f);
  SIM_POSITION(q.w) = pb + vec4(d.db, 0.0f);
}

/// Projects distance constraint c (not a hinge): both ends by solveDistance, weighted by inverse
/// mass.
SIM_INLINE void projectDistance(Constraint c) {
  vec4 pa = SIM_POSITION(c.a), pb = SIM_POSITION(c.b); // a != b: each end is read once
  PairDelta d = solveDistance(pa, pb, c.rest, u.stiffness[c.kind_id & SIM_KIND_MASK]);
  SIM_POSITION(c.a) = pa + vec4(d.da, 0.0f);
  SIM_POSITION(c.b) = pb + vec4(d.db, 0.0f);
}

/// Projects hinge constraint c by projectHinge.
SIM_INLINE void projectHingeConstraint(Constraint c) {
  HingeRange hinge = u.hinge;
  projectHinge((c.kind_id >> SIM_KIND_BITS) - hinge.first);
}

/// Projects constraint c in iteration `iteration` of the substep (one colour's constraints share
/// no particle, so no races), when it projects in that iteration: a hinge by
/// projectHingeConstraint, any other by projectDistance. (A colour is one kind, so the per-colour
/// passes run one of the two in a kernel of its own.)
SIM_INLINE void projectConstraint(Constraint c, uint iteration) {
  if (!projectsInIteration(c.kind_id, iteration)) return;
  if ((c.kind_id & SIM_KIND_MASK) == SIM_KIND_HINGE)
    projectHingeConstraint(c);
  else
    projectDistance(c);
}

/// The crease of hinge k at the end of the substep, where the sheet went (creaseReturn), unless it is torn or
/// degenerate.
SIM_INLINE void creaseHinge(uint k) {
  HingeRange hinge = u.hinge;
  if (torn[hinge.first + k] != 0u) return;
  uvec4 q = gridHinge(k, u.cols, u.rows);
  HingeAngle h = hingeAngle(vec3(SIM_POSITION(q.x)), vec3(SIM_POSITION(q.y)), vec3(SIM_POSITION(q.z)),
                            vec3(SIM_POSITION(q.w)), false);
  CreaseKeys crease = u.crease;
  if (h.valid) hinges[k] = creaseReturn(hinges[k], h.angle, crease.yield_angle, crease.hardening);
}

/// True when triangle t (original id) has lost an edge.
SIM_INLINE bool triangleGone(uint t) {
  uvec2 e = tri_edges[t];
  return torn[e.x] != 0u || torn[e.y] != 0u;
}

/// The air on particle i (SIM_FLAG_AIR): meanAir of airOnTriangle over its live triangles, each
/// at the positions (SIM_POSITION) and previous positions of the start of the substep.
SIM_INLINE vec3 airOnParticle(uint i) {
  vec3 sum = vec3(0.0f);
  uint count = 0u;
  for (uint k = 0u; k < 6u; ++k) {
    uint t = particleTriangle(i, k, u.cols, u.rows);
    if (t == SIM_NONE || triangleGone(t)) continue;
    uvec3 c = gridTriangle(t, u.cols);
    sum += airOnTriangle(vec3(SIM_POSITION(c.x)), vec3(SIM_POSITION(c.y)), vec3(SIM_POSITION(c.z)), vec3(prev[c.x]),
                         vec3(prev[c.y]), vec3(prev[c.z]), u.air);
    ++count;
  }
  return meanAir(sum, count);
}

/// Marks constraint c (ends at pa, pb; not torn yet) when stretched beyond the tear threshold and
/// counts it once; true for the first mark of the substep.
SIM_INLINE bool markTear(Constraint c, vec4 pa, vec4 pb) {
  if (!shouldTear(pa, pb, c.rest, c.kind_id & SIM_KIND_MASK, u.tear_factor, u.tear_kinds)) return false;
  if (atomicExchange(torn[c.kind_id >> SIM_KIND_BITS], 1u) != 0u) return false; // a copy marked it first
  atomicAdd(counters.torn_total, 1u);
  return atomicAdd(counters.torn_new, 1u) == 0u;
}

/// True when no live triangle holds the structural edge from particle a to its grid neighbour b
/// (edgeTriangles in xpbd.h). An edge no triangle holds at all (a sheet one particle wide) holds
/// itself.
SIM_INLINE bool edgeCut(uint a, uint b) {
  uvec2 t = edgeTriangles(a, b, u.cols, u.rows);
  bool held = (t.x != SIM_NONE && !triangleGone(t.x)) || (t.y != SIM_NONE && !triangleGone(t.y));
  return !held && (t.x != SIM_NONE || t.y != SIM_NONE);
}

/// The shorten stage on constraint c, in the colour order of the projection (no two of a colour
/// share a particle): a structural edge longer than the stretch limit is shortened to it from both
/// ends (shortenEdge), unless it is stretched to its tear length (shouldTear), which it is left to.
/// Runs only while limitShortens.
SIM_INLINE void shortenConstraint(Constraint c) {
  if ((c.kind_id & SIM_KIND_MASK) != SIM_KIND_STRUCTURAL) return;
  LimitKeys limit = u.limit;
  vec4 pa = SIM_POSITION(c.a), pb = SIM_POSITION(c.b);
  if (shouldTear(pa, pb, c.rest, SIM_KIND_STRUCTURAL, u.tear_factor, u.tear_kinds)) return;
  PairDelta d = shortenEdge(pa, pb, limit.reach);
  SIM_POSITION(c.a) = pa + vec4(d.da, 0.0f);
  SIM_POSITION(c.b) = pb + vec4(d.db, 0.0f);
}

/// The stretch limit on particle i, in its ring of the limit from `root` (after the projection,
/// ring after ring, so its parents have their places): a free particle farther than u.limit.reach from
/// a parent it is still joined to moves to the nearest point within that reach of its parents
/// (intoBothReaches). An edge stretched to its tear length (shouldTear) is left to tear. The move
/// is a placement, not a step: the previous position moves with it, so the particle keeps its
/// velocity. (A limit whose moves were steps fought the next projection through the shear
/// diagonals, which it does not hold, and pumped energy into the sheet.)
/// (u.limit and the previous position are read whole: in a fleet's shaders, which reach the buffers
/// by device address, a y or a w read on its own came out wrong on lavapipe, a w as the x of an
/// earlier read; the SPIR-V of a small case is right, so the cause is not known.)
SIM_INLINE void limitParticle(uint i, uint root) {
  vec4 q = SIM_POSITION(i);
  if (!(q.w > 0.0f)) return;
  uvec2 parent = limitParents(i, root, u.cols);
  LimitKeys limit = u.limit;
  float reach = limit.reach;
  vec4 px = parent.x != SIM_NONE ? SIM_POSITION(parent.x) : q, py = parent.y != SIM_NONE ? SIM_POSITION(parent.y) : q;
  bool far_x = !withinReach(vec3(q), vec3(px), reach), far_y = !withinReach(vec3(q), vec3(py), reach);
  if (!far_x && !far_y) return;
  // The parents it is joined to by an edge that holds
  bool use_x = parent.x != SIM_NONE && !edgeCut(min(i, parent.x), max(i, parent.x)) &&
               !shouldTear(q, px, limit.rest, SIM_KIND_STRUCTURAL, u.tear_factor, u.tear_kinds);
  bool use_y = parent.y != SIM_NONE && !edgeCut(min(i, parent.y), max(i, parent.y)) &&
               !shouldTear(q, py, limit.rest, SIM_KIND_STRUCTURAL, u.tear_factor, u.tear_kinds);
  if (!(far_x && use_x) && !(far_y && use_y)) return;
  vec3 to = use_x && use_y ? intoBothReaches(vec3(q), vec3(px), vec3(py), reach)
                           : intoReach(vec3(q), vec3(use_x ? px : py), reach);
  vec4 before = prev[i];
  SIM_POSITION(i) = vec4(to, q.w);
  prev[i] = vec4(vec3(before) + (to - vec3(q)), before.w);
}

/// After the tear marks of a substep (and only when something tore): marks a constraint that no
/// longer stands on the sheet, so that no constraint ties two pieces of the triangle mesh: a
/// structural edge no live triangle holds, a bend over such an edge, a shear, tri-bend or hinge
/// that has lost its triangles (unsupported in xpbd.h). Whether a triangle is gone is settled by the tear
/// marks before this pass; the structural edges this pass marks are held by no live triangle, so
/// marking them changes no triangle and the verdicts do not depend on the order.
SIM_INLINE void markUnsupported(Constraint c) {
  uint kind = c.kind_id & SIM_KIND_MASK, id = c.kind_id >> SIM_KIND_BITS;
  if (torn[id] != 0u) return;
  bool cut;
  if (kind == SIM_KIND_STRUCTURAL) {
    cut = edgeCut(c.a, c.b);
  } else if (kind == SIM_KIND_BEND) {
    uint mid = (c.a + c.b) / 2u; // a bend spans two structural edges of a row or a column
    cut = edgeCut(c.a, mid) || edgeCut(mid, c.b);
  } else {
    HingeRange hinge = u.hinge;
    uvec2 t = kind == SIM_KIND_HINGE ? hingeTriangles(id - hinge.first, u.cols, u.rows)
                                     : supportTriangles(c.a, c.b, kind, u.cols);
    cut = unsupported(c.a, c.b, kind, u.cols, triangleGone(t.x), triangleGone(t.y));
  }
  if (!cut) return;
  if (atomicExchange(torn[id], 1u) != 0u) return; // a copy marked it first
  atomicAdd(counters.torn_total, 1u);
  atomicAdd(counters.torn_new, 1u);
}
#endif
