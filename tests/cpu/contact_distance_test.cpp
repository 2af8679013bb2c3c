// The distances penetration-free contact is built on (shaders/shared/distance.h) against closed
// forms and sampled points, the bounded step, and the half-space of a pair within the margin.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "common/sim_helpers.h"
#include "core/intersections.h"
#include "core/stats.h"
#include "cpu/cpu_contact.h"
#include "cpu/cpu_solver.h"
#include "cpu/worker_pool.h"
#include "cpu_runs.h"
#include "shaderio.h"

namespace tender::test {
namespace {

using glm::vec3;
using shaderio::NearestPoints;

/// The vector between the nearest points a NearestPoints names.
vec3 separation(const NearestPoints& c, vec3 x0, vec3 x1, vec3 x2, vec3 x3) {
  return x0 * c.w.x + x1 * c.w.y + x2 * c.w.z + x3 * c.w.w;
}

TEST(ContactDistance, ClosedForms) {
  const vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  // Over the inside: the height; beyond a corner: to the corner; beyond an edge: to the edge
  EXPECT_FLOAT_EQ(shaderio::pointTriangle(vec3(0.25f, 0.25f, 0.5f), a, b, c).d2, 0.25f);
  EXPECT_FLOAT_EQ(shaderio::pointTriangle(vec3(2, 0, 0), a, b, c).d2, 1.0f);
  EXPECT_FLOAT_EQ(shaderio::pointTriangle(vec3(0.5f, -1, 1), a, b, c).d2, 2.0f);
  // Skew segments crossing 0.5 apart; parallel ones side by side; collinear ones with a gap
  EXPECT_FLOAT_EQ(shaderio::segmentSegment(vec3(-1, 0, 0), vec3(1, 0, 0), vec3(0, -1, 0.5f), vec3(0, 1, 0.5f)).d2,
                  0.25f);
  EXPECT_FLOAT_EQ(shaderio::segmentSegment(vec3(0, 0, 0), vec3(1, 0, 0), vec3(0.5f, 0.3f, 0), vec3(2, 0.3f, 0)).d2,
                  0.09f);
  EXPECT_FLOAT_EQ(shaderio::segmentSegment(vec3(0, 0, 0), vec3(1, 0, 0), vec3(1.5f, 0, 0), vec3(3, 0, 0)).d2, 0.25f);
  // Zero-length segments and triangles of no area are points and segments
  EXPECT_FLOAT_EQ(shaderio::segmentSegment(vec3(0, 0, 0), vec3(0, 0, 0), vec3(0, 2, 0), vec3(0, 2, 0)).d2, 4.0f);
  EXPECT_FLOAT_EQ(shaderio::pointTriangle(vec3(0.5f, 1, 0), a, b, vec3(2, 0, 0)).d2, 1.0f);
  EXPECT_FLOAT_EQ(shaderio::pointTriangle(vec3(0, 3, 0), a, a, a).d2, 9.0f);
}

TEST(ContactDistance, NeverAboveTheNearestSampledPointsAndTheWeightsNameThem) {
  // Random triangles and segments, thin and degenerate ones among them: the distance is at most
  // the nearest of a fine sampling of the primitives (it is a minimum), at least that less the
  // sampling's spacing, and the weights give a vector of that length.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  auto point = [&] { return vec3(u(rng), u(rng), u(rng)); };
  constexpr int kSteps = 64;
  for (int trial = 0; trial < 400; ++trial) {
    vec3 a = point(), b = point(), c = point(), p = point();
    if (trial % 10 == 0) c = a + (b - a) * 0.3f; // no area
    const NearestPoints vf = shaderio::pointTriangle(p, a, b, c);
    float sampled = 1e30f, longest = std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
    for (int i = 0; i <= kSteps; ++i)
      for (int j = 0; i + j <= kSteps; ++j) {
        const vec3 q = a + (b - a) * (float(i) / kSteps) + (c - a) * (float(j) / kSteps);
        sampled = std::min(sampled, glm::dot(p - q, p - q));
      }
    ASSERT_TRUE(std::isfinite(vf.d2));
    EXPECT_LE(vf.d2, sampled * 1.0001f + 1e-9f) << trial;
    EXPECT_GE(std::sqrt(vf.d2), std::sqrt(sampled) - 2.0f * longest / kSteps) << trial;
    EXPECT_NEAR(glm::length(separation(vf, p, a, b, c)), std::sqrt(vf.d2), 1e-4f) << trial;

    vec3 q0 = point(), q1 = point();
    if (trial % 10 == 1) q1 = q0 + (b - a) * 0.5f; // parallel
    const NearestPoints ee = shaderio::segmentSegment(a, b, q0, q1);
    sampled = 1e30f;
    for (int i = 0; i <= kSteps; ++i)
      for (int j = 0; j <= kSteps; ++j) {
        const vec3 d = (a + (b - a) * (float(i) / kSteps)) - (q0 + (q1 - q0) * (float(j) / kSteps));
        sampled = std::min(sampled, glm::dot(d, d));
      }
    longest = std::max(glm::length(b - a), glm::length(q1 - q0));
    ASSERT_TRUE(std::isfinite(ee.d2));
    EXPECT_LE(ee.d2, sampled * 1.0001f + 1e-9f) << trial;
    EXPECT_GE(std::sqrt(ee.d2), std::sqrt(sampled) - 2.0f * longest / kSteps) << trial;
    EXPECT_NEAR(glm::length(separation(ee, a, b, q0, q1)), std::sqrt(ee.d2), 1e-4f) << trial;
  }
}

TEST(ContactDistance, ABoundedStepGoesNoFartherThanItsBound) {
  const vec3 x0(1.0f, 2.0f, 3.0f);
  EXPECT_EQ(shaderio::boundedStep(x0, x0 + vec3(0.1f, 0, 0), 0.2f), x0 + vec3(0.1f, 0, 0)); // within: unchanged
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-5.0f, 5.0f);
  for (int k = 0; k < 1000; ++k) {
    const vec3 x(u(rng), u(rng), u(rng));
    const float bound = 0.01f * float(k % 100);
    const vec3 y = shaderio::boundedStep(x0, x, bound);
    EXPECT_LE(glm::length(y - x0), bound * 1.000001f + 1e-6f);
    if (bound == 0.0f) {
      EXPECT_EQ(y, x0);
      continue;
    }
    // Along the step it was to make, not back
    EXPECT_LE(glm::length(glm::cross(y - x0, x - x0)), 1e-4f * glm::length(y - x0) * glm::length(x - x0));
    EXPECT_GT(glm::dot(y - x0, x - x0), 0.0f);
  }
  // The bound is the fraction of the distance less the margin; within the margin, nothing: a pair
  // pressed together stops, and its push, at most a tenth of the distance less half the margin, parts it
  EXPECT_NEAR(shaderio::stepBound(0.25f, 1.0f, 0.4f), 0.4f * (0.5f - SIM_CONTACT_MARGIN), 1e-7f);
  EXPECT_EQ(shaderio::stepBound(1e-8f, 1.0f, 0.4f), 0.0f);
  // The push: a tenth of the distance less half the margin (1e-3 - 5e-5 for a radius of 0.1)
  const vec3 cut = shaderio::contactPushWithin(vec3(0.0f, 3.0f, 4.0f), 1e-6f, 0.1f);
  EXPECT_NEAR(glm::length(cut), 9.5e-5f, 1e-9f);
  EXPECT_NEAR(cut.z / cut.y, 4.0f / 3.0f, 1e-5f);
  EXPECT_EQ(shaderio::contactPushWithin(vec3(1e-5f, 0.0f, 0.0f), 1e-6f, 0.1f), vec3(1e-5f, 0.0f, 0.0f));
  EXPECT_EQ(shaderio::contactPushWithin(vec3(1e-5f, 0.0f, 0.0f), 1e-12f, 0.1f), vec3(0.0f)); // within m/2
  // A pair whose two sides each move their whole bound and push towards the other, substep after
  // substep (the push is the mean of a particle's pairs, so it may point at another primitive than
  // the one it parts the particle from): it never ends closer than the least of its start and half
  // the margin. A push of a tenth of the distance alone let it close by a fifth each substep.
  const float m = SIM_CONTACT_MARGIN;
  for (const float start : {3.0f * m, m, 0.7f * m, 0.5f * m, 0.3f * m}) {
    float d = start, old = start;
    for (int substep = 0; substep < 200; ++substep) {
      const vec3 push = shaderio::contactPushWithin(vec3(1.0f, 0.0f, 0.0f), d * d, 1.0f);
      d -= 2.0f * (shaderio::stepBound(d * d, 1.0f, SIM_CONTACT_FRACTION) + glm::length(push));
      ASSERT_GE(d, 0.999f * std::min(start, 0.5f * m)) << start << " after " << substep;
      old -= 2.0f * (shaderio::stepBound(old * old, 1.0f, SIM_CONTACT_FRACTION) + SIM_CONTACT_PUSH_FRACTION * old);
    }
    EXPECT_LT(old, 1e-2f * m) << start;
  }
}

TEST(ContactDistance, APairWithinTheMarginMayPartAndSlideButNotClose) {
  // A particle a third of the margin above a triangle in the plane z = 0 (contact radius 1): it may
  // not go down at all, it may go up and along as far as its ball, and it is not held where it is
  // (within the margin the bound was once zero in every direction: a particle pressed there stayed
  // until its push, a tenth of its distance less half the margin, parted it)
  const float radius = 1.0f, m = SIM_CONTACT_MARGIN * radius, f = SIM_CONTACT_FRACTION;
  const vec3 p(0.25f, 0.25f, m / 3.0f), a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  const NearestPoints pair = shaderio::pointTriangle(p, a, b, c);
  ASSERT_LT(pair.d2, m * m);
  EXPECT_EQ(shaderio::slideBound(pair.d2, radius, f), shaderio::stepBound(radius * radius, radius, f));
  const shaderio::SlideHalf up = shaderio::slideConstraint(p, a, b, c, pair, false, radius, f, 0);
  EXPECT_EQ(up.h.w, 0.0f);
  EXPECT_NEAR(up.h.z, 1.0f, 1e-6f);
  const vec3 away(0.0f, 0.0f, 0.1f), towards(0.0f, 0.0f, -0.1f), along_up(0.1f, 0.0f, 0.01f);
  EXPECT_EQ(shaderio::slideShare(up, away), 1.0f);
  EXPECT_EQ(shaderio::slideExcess(up, away), vec3(0.0f));
  EXPECT_EQ(shaderio::slideShare(up, along_up), 1.0f);
  EXPECT_EQ(shaderio::slideShare(up, towards), 0.0f);
  // The triangle's corners likewise: away from the particle, not towards it
  const shaderio::SlideHalf down = shaderio::slideConstraint(p, a, b, c, pair, false, radius, f, 1);
  EXPECT_EQ(down.h.w, 0.0f);
  EXPECT_EQ(shaderio::slideShare(down, towards), 1.0f);
  EXPECT_EQ(shaderio::slideShare(down, away), 0.0f);
  // Two primitives that touch have no normal: nothing moves
  const NearestPoints touching = shaderio::pointTriangle(vec3(0.25f, 0.25f, 0.0f), a, b, c);
  EXPECT_EQ(shaderio::slideBound(touching.d2, radius, f), 0.0f);
  EXPECT_LT(shaderio::slideConstraint(vec3(0.25f, 0.25f, 0.0f), a, b, c, touching, false, radius, f, 0).h.w, 0.0f);
}

} // namespace
} // namespace tender::test
