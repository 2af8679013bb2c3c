#include "intersections.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include <gmpxx.h>

namespace tender {
namespace {

// A product of differences of floats, as doubles, is off by a few units in the last place; a
// determinant farther from zero than this part of its terms' magnitude has its sign right (the
// bounds of Shewchuk's predicates are 7.8e-16 and 3.3e-16: this one is a hundred times safer).
constexpr double kFilter = 1e-13;

int sign(double v) { return (v > 0.0) - (v < 0.0); }

int exactOrient3d(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
  mpq_class m[3][3];
  const glm::vec3 p[3] = {a, b, c};
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) m[r][k] = mpq_class(double(p[r][k])) - mpq_class(double(d[k]));
  const mpq_class det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                        m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                        m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  return sgn(det);
}

int exactOrient2d(glm::vec2 a, glm::vec2 b, glm::vec2 c) {
  const mpq_class ax = mpq_class(double(a.x)) - mpq_class(double(c.x)),
                  ay = mpq_class(double(a.y)) - mpq_class(double(c.y));
  const mpq_class bx = mpq_class(double(b.x)) - mpq_class(double(c.x)),
                  by = mpq_class(double(b.y)) - mpq_class(double(c.y));
  const mpq_class det = ax * by - ay * bx;
  return sgn(det);
}

glm::vec2 drop(glm::vec3 p, int axis) {
  return axis == 0 ? glm::vec2(p.y, p.z) : axis == 1 ? glm::vec2(p.z, p.x) : glm::vec2(p.x, p.y);
}

/// An axis whose dropping leaves triangle t a triangle of some area in the plane (-1: t has none).
int projectionAxis(const glm::vec3 t[3]) {
  for (int axis = 2; axis >= 0; --axis)
    if (orient2d(drop(t[0], axis), drop(t[1], axis), drop(t[2], axis)) != 0) return axis;
  return -1;
}

/// p on the segment ab, given the three are collinear: within its bounding box.
bool onSegment(glm::vec2 p, glm::vec2 a, glm::vec2 b) {
  return std::min(a.x, b.x) <= p.x && p.x <= std::max(a.x, b.x) && std::min(a.y, b.y) <= p.y &&
         p.y <= std::max(a.y, b.y);
}

/// Closed segments pq and ab of the plane have a point in common.
bool segmentsMeet(glm::vec2 p, glm::vec2 q, glm::vec2 a, glm::vec2 b) {
  const int o1 = orient2d(p, q, a), o2 = orient2d(p, q, b), o3 = orient2d(a, b, p), o4 = orient2d(a, b, q);
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  return (o1 == 0 && onSegment(a, p, q)) || (o2 == 0 && onSegment(b, p, q)) || (o3 == 0 && onSegment(p, a, b)) ||
         (o4 == 0 && onSegment(q, a, b));
}

/// p in the closed triangle abc of the plane (abc of some area).
bool insideTriangle(glm::vec2 p, glm::vec2 a, glm::vec2 b, glm::vec2 c) {
  const int o1 = orient2d(a, b, p), o2 = orient2d(b, c, p), o3 = orient2d(c, a, p);
  return !((o1 > 0 || o2 > 0 || o3 > 0) && (o1 < 0 || o2 < 0 || o3 < 0));
}

/// The closed segment pq and the closed triangle t (of some area, projectable along `axis`) meet.
bool segmentMeetsTriangle(glm::vec3 p, glm::vec3 q, const glm::vec3 t[3], int axis) {
  const int sp = orient3d(t[0], t[1], t[2], p), sq = orient3d(t[0], t[1], t[2], q);
  if (sp == 0 && sq == 0) { // in the triangle's plane
    const glm::vec2 a = drop(t[0], axis), b = drop(t[1], axis), c = drop(t[2], axis);
    const glm::vec2 p2 = drop(p, axis), q2 = drop(q, axis);
    return insideTriangle(p2, a, b, c) || insideTriangle(q2, a, b, c) || segmentsMeet(p2, q2, a, b) ||
           segmentsMeet(p2, q2, b, c) || segmentsMeet(p2, q2, c, a);
  }
  if (sp * sq > 0) return false; // both on one side
  // The line through p and q crosses the plane (at p or q when on it): inside the closed triangle
  // when it passes on no two different sides of the triangle's edges.
  const int o1 = orient3d(p, q, t[0], t[1]), o2 = orient3d(p, q, t[1], t[2]), o3 = orient3d(p, q, t[2], t[0]);
  return !((o1 > 0 || o2 > 0 || o3 > 0) && (o1 < 0 || o2 < 0 || o3 < 0));
}

struct Box {
  glm::vec3 lo, hi;
};

int64_t cellOf(float x, double inv) { return int64_t(std::floor(double(x) * inv)); }

uint64_t cellKey(int64_t x, int64_t y, int64_t z) {
  uint64_t h = uint64_t(x) * 0x9E3779B97F4A7C15ull;
  h ^= uint64_t(y) * 0xC2B2AE3D27D4EB4Full + (h << 6) + (h >> 2);
  h ^= uint64_t(z) * 0x165667B19E3779F9ull + (h << 6) + (h >> 2);
  return h;
}

} // namespace

int orient3d(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
  const double adx = double(a.x) - d.x, bdx = double(b.x) - d.x, cdx = double(c.x) - d.x;
  const double ady = double(a.y) - d.y, bdy = double(b.y) - d.y, cdy = double(c.y) - d.y;
  const double adz = double(a.z) - d.z, bdz = double(b.z) - d.z, cdz = double(c.z) - d.z;
  const double bc = bdx * cdy, cb = cdx * bdy, ca = cdx * ady, ac = adx * cdy, ab = adx * bdy, ba = bdx * ady;
  const double det = adz * (bc - cb) + bdz * (ca - ac) + cdz * (ab - ba);
  const double permanent = (std::abs(bc) + std::abs(cb)) * std::abs(adz) +
                           (std::abs(ca) + std::abs(ac)) * std::abs(bdz) +
                           (std::abs(ab) + std::abs(ba)) * std::abs(cdz);
  if (std::abs(det) > kFilter * permanent) return sign(det);
  // Every term zero: a difference of floats is zero in double only when it is zero, and products
  // of three of them, at least 2^-447, do not underflow; so the determinant is zero
  if (permanent == 0.0) return 0;
  return exactOrient3d(a, b, c, d);
}

int orient2d(glm::vec2 a, glm::vec2 b, glm::vec2 c) {
  const double left = (double(a.x) - c.x) * (double(b.y) - c.y), right = (double(a.y) - c.y) * (double(b.x) - c.x);
  const double det = left - right;
  if (std::abs(det) > kFilter * (std::abs(left) + std::abs(right))) return sign(det);
  if (left == 0.0 && right == 0.0) return 0; // as in orient3d: every term is zero
  return exactOrient2d(a, b, c);
}

bool trianglesIntersect(const glm::vec3 a[3], const glm::vec3 b[3]) {
  const int axis_a = projectionAxis(a), axis_b = projectionAxis(b);
  // Two triangles meet exactly when an edge of one meets the other: the ends of the segment (or
  // the point) they have in common lie on edges; coplanar, one inside the other has its edges inside.
  if (axis_b >= 0)
    for (int e = 0; e < 3; ++e)
      if (segmentMeetsTriangle(a[e], a[(e + 1) % 3], b, axis_b)) return true;
  if (axis_a >= 0)
    for (int e = 0; e < 3; ++e)
      if (segmentMeetsTriangle(b[e], b[(e + 1) % 3], a, axis_a)) return true;
  return false;
}

IntersectionCount intersectingPairs(const std::vector<glm::vec4>& pos, const std::vector<glm::uvec4>& triangles,
                                    uint32_t count, std::vector<uint8_t>* crossing) {
  IntersectionCount result;
  count = std::min<uint32_t>(count, uint32_t(triangles.size()));
  if (crossing) crossing->assign(count, 0);
  std::vector<uint32_t> live; // triangles with finite corners on the sheet
  std::vector<Box> box(count);
  double extent = 0.0;
  for (uint32_t t = 0; t < count; ++t) {
    const glm::uvec4 c = triangles[t];
    if (c.x >= pos.size() || c.y >= pos.size() || c.z >= pos.size()) continue;
    const glm::vec3 p0(pos[c.x]), p1(pos[c.y]), p2(pos[c.z]);
    box[t] = {glm::min(p0, glm::min(p1, p2)), glm::max(p0, glm::max(p1, p2))};
    const glm::vec3 size = box[t].hi - box[t].lo;
    if (!std::isfinite(size.x + size.y + size.z)) continue;
    live.push_back(t);
    extent += double(std::max(size.x, std::max(size.y, size.z)));
  }
  if (live.size() < 2) return result;
  // A grid of cells twice the mean triangle's size: each triangle in the cells its box overlaps;
  // a pair is tested in the cell of the low corner of its boxes' overlap only.
  const double cell = std::max(2.0 * extent / double(live.size()), 1e-30);
  const double inv = 1.0 / cell;
  constexpr int64_t kMaxCells = 4096; // a triangle over more cells is tested against every other
  std::unordered_map<uint64_t, std::vector<uint32_t>> grid;
  std::vector<uint32_t> large;
  std::vector<uint8_t> is_large(count, 0);
  for (uint32_t t : live) {
    const Box& b = box[t];
    const int64_t x0 = cellOf(b.lo.x, inv), y0 = cellOf(b.lo.y, inv), z0 = cellOf(b.lo.z, inv);
    const int64_t x1 = cellOf(b.hi.x, inv), y1 = cellOf(b.hi.y, inv), z1 = cellOf(b.hi.z, inv);
    const double cells = double(x1 - x0 + 1) * double(y1 - y0 + 1) * double(z1 - z0 + 1);
    if (!(cells <= double(kMaxCells))) {
      large.push_back(t);
      is_large[t] = 1;
      continue;
    }
    for (int64_t z = z0; z <= z1; ++z)
      for (int64_t y = y0; y <= y1; ++y)
        for (int64_t x = x0; x <= x1; ++x) grid[cellKey(x, y, z)].push_back(t);
  }
  auto overlap = [&](uint32_t i, uint32_t j) {
    const Box &a = box[i], &b = box[j];
    return a.lo.x <= b.hi.x && b.lo.x <= a.hi.x && a.lo.y <= b.hi.y && b.lo.y <= a.hi.y && a.lo.z <= b.hi.z &&
           b.lo.z <= a.hi.z;
  };
  auto test = [&](uint32_t i, uint32_t j) {
    const glm::uvec4 ti = triangles[i], tj = triangles[j];
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l)
        if (ti[k] == tj[l]) return; // neighbours on the sheet
    ++result.candidates;
    const glm::vec3 a[3] = {glm::vec3(pos[ti.x]), glm::vec3(pos[ti.y]), glm::vec3(pos[ti.z])};
    const glm::vec3 b[3] = {glm::vec3(pos[tj.x]), glm::vec3(pos[tj.y]), glm::vec3(pos[tj.z])};
    if (!trianglesIntersect(a, b)) return;
    ++result.pairs;
    if (crossing) (*crossing)[i] = (*crossing)[j] = 1;
  };
  for (auto& [key, list] : grid) {
    std::sort(list.begin(), list.end()); // a triangle once, even where two of its cells share a key
    list.erase(std::unique(list.begin(), list.end()), list.end());
    for (size_t m = 0; m < list.size(); ++m)
      for (size_t n = m + 1; n < list.size(); ++n) {
        const uint32_t i = list[m], j = list[n];
        if (!overlap(i, j)) continue;
        const glm::vec3 lo = glm::max(box[i].lo, box[j].lo);
        if (cellKey(cellOf(lo.x, inv), cellOf(lo.y, inv), cellOf(lo.z, inv)) != key) continue;
        test(i, j);
      }
  }
  for (uint32_t i : large)
    for (uint32_t j : live)
      if (j != i && (!is_large[j] || j > i) && overlap(i, j)) test(i, j);
  return result;
}

} // namespace tender
