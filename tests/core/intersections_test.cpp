// The intersection judge: analytic cases, an independent exact test (separating axes in GMP
// rationals) on many random and degenerate pairs, and its grid against every pair of a mesh.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include <gmpxx.h>

#include "core/intersections.h"

namespace tender {
namespace {

using V = glm::vec3;

bool meet(V a0, V a1, V a2, V b0, V b1, V b2) {
  const V a[3] = {a0, a1, a2}, b[3] = {b0, b1, b2};
  const bool ab = trianglesIntersect(a, b), ba = trianglesIntersect(b, a);
  EXPECT_EQ(ab, ba); // symmetric
  return ab;
}

TEST(Intersections, AnalyticCases) {
  const V a0(0, 0, 0), a1(2, 0, 0), a2(0, 2, 0);
  // Crossing the plane through the interior; beside it; above it
  EXPECT_TRUE(meet(a0, a1, a2, V(0.5f, 0.5f, -1), V(0.5f, 0.5f, 1), V(3, 3, 0.5f)));
  EXPECT_FALSE(meet(a0, a1, a2, V(3, 3, -1), V(3, 3, 1), V(4, 4, 0)));
  EXPECT_FALSE(meet(a0, a1, a2, V(0, 0, 1), V(2, 0, 1), V(0, 2, 1)));
  // Touching: a vertex on the face, an edge along an edge, vertex to vertex
  EXPECT_TRUE(meet(a0, a1, a2, V(0.5f, 0.5f, 0), V(0.5f, 0.5f, 1), V(1, 0.5f, 1)));
  EXPECT_TRUE(meet(a0, a1, a2, V(0.5f, 0, 0), V(1.5f, 0, 0), V(1, 0, 1)));
  EXPECT_TRUE(meet(a0, a1, a2, V(2, 0, 0), V(3, 0, 1), V(3, 1, 0)));
  // A hair's breadth off: one float step above the face
  const float up = std::nextafter(0.0f, 1.0f);
  EXPECT_FALSE(meet(a0, a1, a2, V(0.5f, 0.5f, up), V(0.5f, 0.5f, 1), V(1, 0.5f, 1)));
  // Coplanar: overlapping, one inside the other, apart, sharing an edge's part
  EXPECT_TRUE(meet(a0, a1, a2, V(1, 1, 0), V(-1, 1, 0), V(1, -1, 0)));
  EXPECT_TRUE(meet(a0, a1, a2, V(0.2f, 0.2f, 0), V(0.5f, 0.2f, 0), V(0.2f, 0.5f, 0)));
  EXPECT_FALSE(meet(a0, a1, a2, V(3, 3, 0), V(4, 3, 0), V(3, 4, 0)));
  EXPECT_TRUE(meet(a0, a1, a2, V(0.5f, 0, 0), V(1, -1, 0), V(1.5f, 0, 0)));
  // Of no area: a segment through the face meets it, a point beside it does not; two never
  EXPECT_TRUE(meet(a0, a1, a2, V(0.5f, 0.5f, -1), V(0.5f, 0.5f, 1), V(0.5f, 0.5f, 0.5f)));
  EXPECT_FALSE(meet(a0, a1, a2, V(5, 5, 5), V(5, 5, 5), V(5, 5, 5)));
  EXPECT_FALSE(meet(a0, a1, a0, V(0, 0, 0), V(0, 0, 0), V(1, 1, 1)));
}

// An independent judge: closed triangles (of some area) are apart exactly when some axis
// separates them strictly: a normal, a cross product of two edges, or, coplanar, an edge's normal
// in the plane. In exact rationals.
using Q = mpq_class;
struct Q3 {
  Q x, y, z;
};
Q3 q3(V v) { return {Q(double(v.x)), Q(double(v.y)), Q(double(v.z))}; }
Q3 sub(const Q3& a, const Q3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Q3 crossQ(const Q3& a, const Q3& b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
Q dotQ(const Q3& a, const Q3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
bool zero(const Q3& a) { return sgn(a.x) == 0 && sgn(a.y) == 0 && sgn(a.z) == 0; }

bool separatingAxes(const V a[3], const V b[3]) {
  Q3 p[3], q[3], ep[3], eq[3];
  for (int k = 0; k < 3; ++k) p[k] = q3(a[k]), q[k] = q3(b[k]);
  for (int k = 0; k < 3; ++k) ep[k] = sub(p[(k + 1) % 3], p[k]), eq[k] = sub(q[(k + 1) % 3], q[k]);
  const Q3 np = crossQ(ep[0], ep[1]), nq = crossQ(eq[0], eq[1]);
  std::vector<Q3> axes = {np, nq};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) axes.push_back(crossQ(ep[i], eq[j]));
  for (int i = 0; i < 3; ++i) axes.push_back(crossQ(np, ep[i])), axes.push_back(crossQ(nq, eq[i]));
  for (const Q3& axis : axes) {
    if (zero(axis)) continue;
    Q lo_p = dotQ(axis, p[0]), hi_p = lo_p, lo_q = dotQ(axis, q[0]), hi_q = lo_q;
    for (int k = 1; k < 3; ++k) {
      const Q dp = dotQ(axis, p[k]), dq = dotQ(axis, q[k]);
      if (dp < lo_p) lo_p = dp;
      if (dp > hi_p) hi_p = dp;
      if (dq < lo_q) lo_q = dq;
      if (dq > hi_q) hi_q = dq;
    }
    if (hi_p < lo_q || hi_q < lo_p) return false;
  }
  return true;
}

TEST(Intersections, AgreeWithSeparatingAxesInExactRationals) {
  // Small integer corners (many coplanar, touching and collinear cases) and floats a few steps
  // from them (the rounding a double would get wrong)
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> small(-2, 2), steps(-2, 2), kind(0, 2);
  uint64_t met = 0, judged = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    V a[3], b[3];
    const int k = kind(rng);
    for (V* t : {a, b})
      for (int c = 0; c < 3; ++c)
        for (int axis = 0; axis < 3; ++axis) {
          float v = float(small(rng));
          if (k == 1) v = v * 0.1f + 0.3f;
          if (k == 2)
            for (int s = steps(rng); s != 0; s += s > 0 ? -1 : 1) v = std::nextafter(v, s > 0 ? 10.0f : -10.0f);
          t[c][axis] = v;
        }
    const V ea = glm::cross(a[1] - a[0], a[2] - a[0]), eb = glm::cross(b[1] - b[0], b[2] - b[0]);
    if (glm::dot(ea, ea) == 0.0f || glm::dot(eb, eb) == 0.0f) continue; // of some area (the axes need it)
    ++judged;
    const bool want = separatingAxes(a, b);
    met += want;
    ASSERT_EQ(trianglesIntersect(a, b), want) << "trial " << trial;
  }
  std::printf("intersections: %llu of %llu random pairs meet\n", static_cast<unsigned long long>(met),
              static_cast<unsigned long long>(judged));
  EXPECT_GT(met, judged / 10);
  EXPECT_LT(met, judged - judged / 10);
}

TEST(Intersections, TheGridFindsEveryPairThatMeets) {
  // A 12 x 12 sheet crumpled at random (so its triangles cross each other) against every pair
  const uint32_t n = 12;
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> jitter(-0.9f, 0.9f);
  std::vector<glm::vec4> pos;
  for (uint32_t j = 0; j < n; ++j)
    for (uint32_t i = 0; i < n; ++i) pos.emplace_back(float(i) * 0.3f + jitter(rng), jitter(rng), float(j) * 0.3f, 1);
  std::vector<glm::uvec4> tris;
  for (uint32_t j = 0; j + 1 < n; ++j)
    for (uint32_t i = 0; i + 1 < n; ++i) {
      const uint32_t tl = j * n + i, bl = tl + n;
      tris.emplace_back(tl, bl, bl + 1, 0);
      tris.emplace_back(tl, bl + 1, tl + 1, 0);
    }
  uint64_t brute = 0;
  for (size_t i = 0; i < tris.size(); ++i)
    for (size_t j = i + 1; j < tris.size(); ++j) {
      bool shared = false;
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) shared |= tris[i][k] == tris[j][l];
      if (shared) continue;
      const V a[3] = {V(pos[tris[i].x]), V(pos[tris[i].y]), V(pos[tris[i].z])};
      const V b[3] = {V(pos[tris[j].x]), V(pos[tris[j].y]), V(pos[tris[j].z])};
      brute += trianglesIntersect(a, b);
    }
  const IntersectionCount c = intersectingPairs(pos, tris, uint32_t(tris.size()));
  std::printf("intersections: %llu pairs of %zu triangles meet (%llu candidates)\n",
              static_cast<unsigned long long>(c.pairs), tris.size(), static_cast<unsigned long long>(c.candidates));
  EXPECT_GT(brute, 20u);
  EXPECT_EQ(c.pairs, brute);
  // The sheet laid flat: neighbours touch, nothing else
  for (glm::vec4& p : pos) p.y = 0.0f, p.x = float(uint32_t(&p - pos.data()) % n) * 0.3f;
  EXPECT_EQ(intersectingPairs(pos, tris, uint32_t(tris.size())).pairs, 0u);
  // Only the first `count` triangles are live
  EXPECT_EQ(intersectingPairs(pos, tris, 0).pairs, 0u);
}

} // namespace
} // namespace tender
