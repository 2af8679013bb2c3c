// The stretch limit's geometry, shared by GLSL and C++ (xpbd.h includes it after the grid's
// topology): its roots and rings on the grid, the parents a particle is held within reach of, the
// shorten stage's edges, and the nearest point within reach of one or two parents.
#ifndef SIM_LIMIT_H
#define SIM_LIMIT_H

/// The stretch limit (SimUniforms::limit) runs out from a root particle, ring after ring: ring k
/// holds the particles k steps along the grid's rows and columns from it, and each particle is
/// held within reach of its parents, its neighbours one step nearer the root in its row and in its
/// column, which ring k - 1 has already placed. The root: the grabbed particle, else the sheet's
/// middle.
SIM_INLINE uint limitRoot(uint grab_index, uint cols, uint rows) {
  return grab_index != SIM_NONE ? grab_index : (rows / 2u) * cols + cols / 2u;
}

/// The last ring of the stretch limit from `root` (its farthest corner).
SIM_INLINE uint limitRings(uint root, uint cols, uint rows) {
  uint x = root % cols, y = root / cols;
  return max(x, cols - 1u - x) + max(y, rows - 1u - y);
}

/// Steps along the grid's rows and columns from particle a to particle b.
SIM_INLINE uint gridSteps(uint a, uint b, uint cols) {
  uint ax = a % cols, ay = a / cols, bx = b % cols, by = b / cols;
  return (ax > bx ? ax - bx : bx - ax) + (ay > by ? ay - by : by - ay);
}

/// The roots the stretch limit runs from: those SimUniforms::limit_roots names (w > 0: the pins
/// of a sheet no hand holds, Simulation::makeUniforms), else the one of limitRoot. With several,
/// each particle belongs to the root nearest it along the grid (limitRootOf) and is placed in its
/// ring around that root, after its parents towards it: each pin holds the edges around it. (Rings
/// from the middle of a sheet hanging from its corners hold none at the pins: 1.54 at 128 x 192;
/// from one corner, 1.09 at the other.)
SIM_INLINE uvec4 limitRootSet(uvec4 roots, uint grab_index, uint cols, uint rows) {
  return roots.w > 0u ? roots : uvec4(limitRoot(grab_index, cols, rows), SIM_NONE, SIM_NONE, 1u);
}

/// Which of `count` roots at columns rx and rows ry the particle at column x, row y belongs to: the
/// nearest along the grid, the first of equals. A parent of it (one step nearer that root) is
/// nearer that root too, so it lies in an earlier ring. (No division: a ring's walk asks it of
/// every slot, and a CPU device divides slowly.)
SIM_INLINE uint limitRootAt(uint x, uint y, uvec4 rx, uvec4 ry, uint count) {
  uint best = 0u, steps = 0xFFFFFFFFu;
  for (uint j = 0u; j < count; ++j) {
    uint s = (x > rx[j] ? x - rx[j] : rx[j] - x) + (y > ry[j] ? y - ry[j] : ry[j] - y);
    if (s < steps) {
      best = j;
      steps = s;
    }
  }
  return best;
}

/// Which of `roots` (limitRootSet) particle i belongs to (limitRootAt).
SIM_INLINE uint limitRootOf(uint i, uvec4 roots, uint cols) {
  return limitRootAt(i % cols, i / cols, roots % cols, roots / cols, roots.w);
}

/// The last ring of the stretch limit from `roots`: no particle lies farther from its own root.
SIM_INLINE uint limitRingsOf(uvec4 roots, uint cols, uint rows) {
  uint last = 0u;
  for (uint j = 0u; j < roots.w; ++j) last = max(last, limitRings(roots[j], cols, rows));
  return last;
}

/// The fewest steps along the grid from the particle at column x, row y to one of `count` roots at
/// columns rx and rows ry: the ring it is placed in (limitRootAt names that root).
SIM_INLINE uint limitStepsAt(uint x, uint y, uvec4 rx, uvec4 ry, uint count) {
  uint steps = 0xFFFFFFFFu;
  for (uint j = 0u; j < count; ++j)
    steps = min(steps, (x > rx[j] ? x - rx[j] : rx[j] - x) + (y > ry[j] ? y - ry[j] : ry[j] - y));
  return steps;
}

/// The last ring of the stretch limit from `roots` exactly (limitRingsOf bounds it: 78 for a 32 x
/// 48 sheet from its two top corners, where the farthest particle from its own pin is 62 steps
/// away): the most of limitStepsAt over the grid. Along a row each root's steps fall to its column
/// and rise after it, so their least is highest at the row's ends or where one root's rising steps
/// meet another's falling ones, at (rx_i + rx_j + dy_j - dy_i) / 2 (dy: the rows to the root):
/// those columns of each row are all it weighs. Rows x (2 + 4 x pairs of roots) places, for the
/// host (SimUniforms::limit.last_ring).
SIM_INLINE uint limitLastRing(uvec4 roots, uint cols, uint rows) {
  uvec4 rx = roots % cols, ry = roots / cols;
  uint count = roots.w, last = 0u;
  for (uint y = 0u; y < rows; ++y) {
    last = max(last, max(limitStepsAt(0u, y, rx, ry, count), limitStepsAt(cols - 1u, y, rx, ry, count)));
    for (uint i = 0u; i < count; ++i)
      for (uint j = 0u; j < count; ++j) {
        if (i == j) continue;
        int twice = int(rx[i] + rx[j]) + abs(int(y) - int(ry[j])) - abs(int(y) - int(ry[i]));
        for (int up = 0; up <= 1; ++up) {
          int x = (twice + up) >> 1;
          if (x >= 0 && x < int(cols)) last = max(last, limitStepsAt(uint(x), y, rx, ry, count));
        }
      }
  }
  return last;
}

/// Slots of a ring (ringParticle): two for each line of the grid's shorter side.
SIM_INLINE uint limitSlots(uint cols, uint rows) { return 2u * min(cols, rows); }

/// Rings one dispatch of the stretch limit walks with a workgroup of `invocations`
/// (SIM_LIMIT_LOOP_BUDGET; a ring walks the slots of each root, limitRing), and the rings a sheet
/// can have from any root: its dispatches cover rings 1 to cols + rows - 2.
SIM_INLINE uint limitRingsPerDispatch(uint cols, uint rows, uint invocations) {
  uint per_ring = 1u + SIM_LIMIT_ROOTS * (1u + (limitSlots(cols, rows) + invocations - 1u) / invocations);
  return max(1u, SIM_LIMIT_LOOP_BUDGET / per_ring);
}
SIM_INLINE uint limitMostRings(uint cols, uint rows) { return cols + rows - 2u; }

/// The particle of ring k around `root` that slot t (< limitSlots) names, or SIM_NONE: line t / 2
/// of the grid's shorter side (a row when rows <= cols, else a column), on the side of the root
/// that t's lowest bit says. No two slots of a ring name one particle.
SIM_INLINE uint ringParticle(uint root, uint k, uint t, uint cols, uint rows) {
  bool by_row = rows <= cols;
  uint lines = by_row ? rows : cols, along = by_row ? cols : rows;
  uint line0 = by_row ? root / cols : root % cols, at0 = by_row ? root % cols : root / cols;
  uint line = t >> 1u, side = t & 1u;
  if (line >= lines) return SIM_NONE;
  uint across = line > line0 ? line - line0 : line0 - line;
  if (across > k) return SIM_NONE;
  uint d = k - across;
  if ((d == 0u && side == 1u) || (side == 0u ? d > at0 : at0 + d >= along)) return SIM_NONE;
  uint at = side == 0u ? at0 - d : at0 + d;
  return by_row ? line * cols + at : at * cols + line;
}

/// The parents of particle i (not the root) in the stretch limit from `root`: x its neighbour one
/// step nearer the root's column in its row, y one step nearer the root's row in its column
/// (SIM_NONE where it shares the root's column or row).
SIM_INLINE uvec2 limitParents(uint i, uint root, uint cols) {
  uint x = i % cols, y = i / cols, rx = root % cols, ry = root / cols;
  uint in_row = x == rx ? SIM_NONE : (x < rx ? i + 1u : i - 1u);
  uint in_col = y == ry ? SIM_NONE : (y < ry ? i + cols : i - cols);
  return uvec2(in_row, in_col);
}

/// True when the shorten stage visits a colour whose first constraint is `kind_id`: a colour holds
/// its structural edges first (buildSheet makes them first; the colouring's sort and the compaction
/// keep the order), so one that starts with another kind (a shear's, a hinge's) holds no edge.
SIM_INLINE bool shortensColour(uint kind_id) { return (kind_id & SIM_KIND_MASK) == SIM_KIND_STRUCTURAL; }

/// An edge from pa to pb longer than `reach` shortened to it from both ends alike (an end that
/// does not move, w = 0, leaves the whole to the other): a step, which the previous positions do
/// not follow, so the speed it takes out of the stretch is gone.
SIM_INLINE PairDelta shortenEdge(vec4 pa, vec4 pb, float reach) {
  PairDelta r;
  r.da = vec3(0.0f);
  r.db = vec3(0.0f);
  float wa = pa.w > 0.0f ? 1.0f : 0.0f, wb = pb.w > 0.0f ? 1.0f : 0.0f;
  vec3 d = vec3(pb) - vec3(pa);
  float len2 = dot3(d, d);
  if (!(wa + wb > 0.0f) || !(len2 > reach * reach)) return r;
  float len = simSqrt(len2);
  vec3 c = d * simDiv(len - reach, len * (wa + wb));
  r.da = c * wa;
  r.db = -(c * wb);
  return r;
}

/// True when c lies within `reach` of a.
SIM_INLINE bool withinReach(vec3 c, vec3 a, float reach) {
  vec3 d = c - a;
  return !(dot3(d, d) > reach * reach);
}

/// The point nearest c within `reach` of a.
SIM_INLINE vec3 intoReach(vec3 c, vec3 a, float reach) {
  vec3 d = c - a;
  float len = simSqrt(dot3(d, d));
  return len > reach ? a + d * simDiv(reach, len) : c;
}

/// The point nearest c within `reach` of both a and b (the two parents of the stretch limit):
/// within one of the balls and inside the other, else on the circle where their spheres meet;
/// their midpoint where the balls do not meet, or where c lies on the line through a and b.
SIM_INLINE vec3 intoBothReaches(vec3 c, vec3 a, vec3 b, float reach) {
  vec3 ca = intoReach(c, a, reach);
  if (withinReach(ca, b, reach)) return ca;
  vec3 cb = intoReach(c, b, reach);
  if (withinReach(cb, a, reach)) return cb;
  vec3 m = (a + b) * 0.5f, ab = b - a;
  float half2 = dot3(ab, ab) * 0.25f, reach2 = reach * reach;
  if (!(half2 < reach2)) return m;
  vec3 v = c - m;
  v = v - ab * simDiv(dot3(v, ab), dot3(ab, ab)); // c's offset from the axis, in the circle's plane
  float len = simSqrt(dot3(v, v));
  return len > 0.0f ? m + v * simDiv(simSqrt(reach2 - half2), len) : m;
}

#endif
