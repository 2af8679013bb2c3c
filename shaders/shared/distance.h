// Distances between the sheet's primitives, shared by GLSL and C++: the nearest points of a
// particle and a segment or a triangle, and of two segments, as weights of their particles. Pure
// geometry; what contact does with them is contact.h's.
#ifndef SIM_DISTANCE_H
#define SIM_DISTANCE_H
#include "exact_math.h"

/// The nearest points of two primitives of up to four particles: w the weights that make the
/// vector from the second primitive's nearest point to the first's, sum_k w[k] x[k], and d2 its
/// squared length.
struct NearestPoints {
  vec4 w;
  float d2;
};

/// Parameter in [0, 1] of the point of the segment a-b nearest to p (0 when a == b).
SIM_INLINE float segmentParameter(vec3 p, vec3 a, vec3 b) {
  vec3 ab = b - a;
  float l2 = dot3(ab, ab);
  return l2 > 0.0f ? clamp(simDiv(dot3(p - a, ab), l2), 0.0f, 1.0f) : 0.0f;
}

/// Particle p against the segment a-b: weights (1, -(1 - t), -t) and the squared distance.
SIM_INLINE NearestPoints pointSegment(vec3 p, vec3 a, vec3 b) {
  float t = segmentParameter(p, a, b);
  vec3 d = (p - a) - (b - a) * t;
  NearestPoints c;
  c.w = vec4(1.0f, t - 1.0f, -t, 0.0f);
  c.d2 = dot3(d, d);
  return c;
}

/// Particle p against the triangle a, b, c: its plane when p lies over the inside, otherwise the
/// nearest edge. Weights (1, -barycentric a, b, c). A triangle of no area is its edges. Finite for
/// finite input.
SIM_INLINE NearestPoints pointTriangle(vec3 p, vec3 a, vec3 b, vec3 c) {
  vec3 n = cross3(b - a, c - a);
  float n2 = dot3(n, n);
  float wa = dot3(cross3(c - b, p - b), n), wb = dot3(cross3(a - c, p - c), n), wc = dot3(cross3(b - a, p - a), n);
  NearestPoints r;
  if (n2 > 0.0f && wa >= 0.0f && wb >= 0.0f && wc >= 0.0f) {
    float plane = dot3(p - a, n);
    r.w = vec4(1.0f, -simDiv(wa, n2), -simDiv(wb, n2), -simDiv(wc, n2));
    r.d2 = simDiv(plane * plane, n2);
    if (r.d2 >= 0.0f && r.d2 <= 3.0e38f) return r;
  }
  NearestPoints ab = pointSegment(p, a, b), bc = pointSegment(p, b, c), ca = pointSegment(p, c, a);
  r = ab;
  if (bc.d2 < r.d2) r = NearestPoints(vec4(1.0f, 0.0f, bc.w.y, bc.w.z), bc.d2);
  if (ca.d2 < r.d2) r = NearestPoints(vec4(1.0f, ca.w.z, 0.0f, ca.w.y), ca.d2);
  return r;
}

/// Squared distance from p to the triangle a, b, c (pointTriangle).
SIM_INLINE float pointTriangleDistance2(vec3 p, vec3 a, vec3 b, vec3 c) { return pointTriangle(p, a, b, c).d2; }

/// The segments p0-p1 and q0-q1: weights (1 - s, s, -(1 - t), -t) of their nearest points by
/// clamped parameters (parallel and zero-length segments included). Finite for finite input.
SIM_INLINE NearestPoints segmentSegment(vec3 p0, vec3 p1, vec3 q0, vec3 q1) {
  vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  float a = dot3(d1, d1), e = dot3(d2, d2), f = dot3(d2, r);
  float s = 0.0f, t = 0.0f;
  float b = dot3(d1, d2);
  float denom = a * e - b * b;
  if (a <= 0.0f && e <= 0.0f) {
    s = 0.0f;
    t = 0.0f;
  } else if (a <= 0.0f) {
    t = clamp(simDiv(f, e), 0.0f, 1.0f);
  } else {
    float c = dot3(d1, r);
    if (e <= 0.0f) {
      s = clamp(simDiv(-c, a), 0.0f, 1.0f);
    } else {
      s = denom > 0.0f ? clamp(simDiv(b * f - c * e, denom), 0.0f, 1.0f) : 0.0f;
      t = simDiv(b * s + f, e);
      if (t < 0.0f) {
        t = 0.0f;
        s = clamp(simDiv(-c, a), 0.0f, 1.0f);
      } else if (t > 1.0f) {
        t = 1.0f;
        s = clamp(simDiv(b - c, a), 0.0f, 1.0f);
      }
    }
  }
  vec3 d = (p0 + d1 * s) - (q0 + d2 * t);
  NearestPoints best;
  best.w = vec4(1.0f - s, s, t - 1.0f, -t);
  best.d2 = dot3(d, d);
  if (!(best.d2 >= 0.0f && best.d2 <= 3.0e38f)) best.d2 = 3.0e38f;
  // Parallel segments are nearest at an end of one of them; nearly parallel ones (the division
  // above then rounds wide) compare the ends too
  if (denom <= 1e-4f * a * e) {
    NearestPoints k = pointSegment(p0, q0, q1);
    if (k.d2 < best.d2) best = NearestPoints(vec4(1.0f, 0.0f, k.w.y, k.w.z), k.d2);
    k = pointSegment(p1, q0, q1);
    if (k.d2 < best.d2) best = NearestPoints(vec4(0.0f, 1.0f, k.w.y, k.w.z), k.d2);
    k = pointSegment(q0, p0, p1);
    if (k.d2 < best.d2) best = NearestPoints(vec4(-k.w.y, -k.w.z, -1.0f, 0.0f), k.d2);
    k = pointSegment(q1, p0, p1);
    if (k.d2 < best.d2) best = NearestPoints(vec4(-k.w.y, -k.w.z, 0.0f, -1.0f), k.d2);
  }
  return best;
}

/// Squared distance between the segments p0-p1 and q0-q1 (segmentSegment).
SIM_INLINE float segmentDistance2(vec3 p0, vec3 p1, vec3 q0, vec3 q1) { return segmentSegment(p0, p1, q0, q1).d2; }

#endif
