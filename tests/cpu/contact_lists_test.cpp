// The CPU contact's pair lists (cpu/cpu_contact.h): kept, turned and repaired, they hold every
// pair closer than the radius, built before two layers meet, and the bounds and pushes are those
// of a brute-force search.
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

// `layers` layers of a side x side grid 0.15 apart, a triangle mesh each: layer l at height gap x l,
// moved by shift x l in its plane
struct Layers {
  std::vector<glm::vec4> pos;
  std::vector<glm::uvec4> triangles;
};
Layers stackedLayers(uint32_t side, uint32_t layers, float gap, glm::vec2 shift) {
  Layers out;
  out.pos.resize(layers * side * side);
  for (uint32_t l = 0; l < layers; ++l)
    for (uint32_t y = 0; y < side; ++y)
      for (uint32_t x = 0; x < side; ++x) {
        const uint32_t i = (l * side + y) * side + x;
        out.pos[i] = glm::vec4(0.15f * float(x) + shift.x * float(l), gap * float(l),
                               0.15f * float(y) + shift.y * float(l), 1.0f);
        if (x + 1 < side && y + 1 < side) {
          out.triangles.push_back(glm::uvec4(i, i + 1, i + side, 0));
          out.triangles.push_back(glm::uvec4(i + 1, i + side + 1, i + side, 0));
        }
      }
  return out;
}

// The contact's uniforms for a radius (its thickness and fixed point as the solver sets them), the
// floor far below
shaderio::SimUniforms contactUniforms(float radius) {
  shaderio::SimUniforms u{};
  const float thickness = radius * SIM_CONTACT_THICKNESS;
  u.contact = {radius, SIM_CONTACT_FRACTION, thickness, SIM_CONTACT_FIXED / thickness};
  u.floor_y = -10.0f;
  return u;
}

// Pair lists kept (Lists::Repaired: standing, turned, by clusters, repaired) against lists built
// whole at every call, on the same positions: the same bounds and pushes, and the same cuts of
// random steps up to 0.3 radius to the pairs' half-spaces (every pair closer than the radius has
// one, so a pair missing from the kept lists shows)
struct KeptAgainstRebuilt {
  WorkerPool pool{2};
  CpuContact rebuilt{pool, CpuContact::Lists::Rebuilt}, kept{pool, CpuContact::Lists::Repaired};
  std::vector<float> bound_a, bound_b, share_a, share_b;
  std::vector<glm::vec4> push_a, push_b, moved, passed_a, passed_b, excess_a, excess_b;

  testing::AssertionResult call(const std::vector<glm::vec4>& pos, const std::vector<glm::vec4>& prev,
                                const std::vector<glm::uvec4>& triangles, const shaderio::SimUniforms& u,
                                std::mt19937& rng) {
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    rebuilt.computeBounds(pos, prev, triangles, uint32_t(triangles.size()), u, 1, bound_a, push_a);
    kept.computeBounds(pos, prev, triangles, uint32_t(triangles.size()), u, 1, bound_b, push_b);
    moved.resize(pos.size());
    for (size_t i = 0; i < pos.size(); ++i)
      moved[i] = pos[i] + glm::vec4(unit(rng), unit(rng), unit(rng), 0.0f) * 0.3f * u.contact.radius;
    rebuilt.slide(pos, moved, u, passed_a, excess_a, share_a);
    kept.slide(pos, moved, u, passed_b, excess_b, share_b);
    if (!sameBytes(bound_a, bound_b)) return testing::AssertionFailure() << "the bounds differ";
    if (!sameBytes(push_a, push_b)) return testing::AssertionFailure() << "the pushes differ";
    if (!sameBytes(passed_a, passed_b)) return testing::AssertionFailure() << "the passed steps differ";
    if (!sameBytes(excess_a, excess_b)) return testing::AssertionFailure() << "the excesses differ";
    if (!sameBytes(share_a, share_b)) return testing::AssertionFailure() << "the shares differ";
    return testing::AssertionSuccess();
  }
};

TEST(ContactLists, ARepairKeepsEveryPairCloserThanTheRadius) {
  // Two layers of a 16 x 16 grid a radius apart, a triangle mesh of each, and at each call a few
  // particles carried up to half a radius and the rest nudged: lists repaired where particles
  // travelled too far hold every pair closer than the radius (KeptAgainstRebuilt)
  constexpr uint32_t kLayer = 16 * 16;
  const float radius = 0.1f;
  auto [pos, triangles] = stackedLayers(16, 2, radius, glm::vec2(0.0f, 0.05f));
  const shaderio::SimUniforms u = contactUniforms(radius);
  KeptAgainstRebuilt lists;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  uint32_t contacts = 0;
  for (uint32_t call = 0; call < 120; ++call) {
    const std::vector<glm::vec4> prev = pos;
    for (glm::vec4& p : pos) {
      const float reach = rng() % 40 == 0 ? 0.5f * radius : 0.03f * radius;
      p += glm::vec4(unit(rng), unit(rng), unit(rng), 0.0f) * reach;
    }
    ASSERT_TRUE(lists.call(pos, prev, triangles, u, rng)) << "call " << call;
    contacts += uint32_t(lists.rebuilt.contacts());
  }
  std::printf("%u particles in contact a call; lists built whole %u times, or %u times and repaired %u times\n",
              contacts / 120u, lists.rebuilt.listBuilds(), lists.kept.listBuilds(), lists.kept.listRepairs());
  EXPECT_GT(contacts / 120u, kLayer);
  EXPECT_GT(lists.kept.listRepairs(), 60u);
  EXPECT_EQ(lists.rebuilt.listRepairs(), 0u);
}

TEST(ContactLists, ASheetThatTurnsAndStretchesKeepsItsListsAndEveryPairCloserThanTheRadius) {
  // Two layers of a 40 x 40 grid 0.6 radius apart, one over half of the other, turned about a tilted axis by up to 1.2
  // rad, stretched in their plane by 0.4 % about their middle over the 20th to the 29th call, the upper one slid
  // farther over the lower by two radii from the 40th to the 50th, and every particle nudged: the corners travel
  // hundreds of times the lists' travel, the stretch alone carries particles farther from one another than it lets, and
  // the slide brings new pairs within the radius. The lists stand through the turn (taken out of the travels) and the
  // stretch (clusters next to each other travel alike), not through the slide, and hold every pair closer than the
  // radius (KeptAgainstRebuilt).
  constexpr uint32_t kSide = 40, kCalls = 60;
  const float radius = 0.1f;
  const auto [rest, triangles] = stackedLayers(kSide, 2, 0.6f * radius, glm::vec2(0.075f * kSide, 0.05f));
  const uint32_t n = uint32_t(rest.size());
  vec3 middle(0.0f);
  for (const glm::vec4& p : rest) middle += vec3(p) / float(n);
  const shaderio::SimUniforms u = contactUniforms(radius);
  KeptAgainstRebuilt lists;
  const CpuContact& kept = lists.kept;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  const vec3 axis = glm::normalize(vec3(0.3f, 1.0f, 0.2f));
  std::vector<glm::vec4> pos = rest, prev;
  uint64_t contacts = 0;
  float widest = 0.0f;
  uint32_t turned = 0, held = 0; // the calls of the first two phases the lists stood by the turn, the clusters
  for (uint32_t call = 0; call < kCalls; ++call) {
    prev = pos;
    const float t = float(call) / float(kCalls - 1);
    const float stretch = 1.0f + 0.004f * std::clamp((float(call) - 20.0f) / 9.0f, 0.0f, 1.0f);
    const float slide = 2.0f * radius * std::clamp((float(call) - 40.0f) / 10.0f, 0.0f, 1.0f);
    const glm::mat3 turn = glm::mat3(glm::rotate(glm::mat4(1.0f), 1.2f * t, axis));
    for (uint32_t i = 0; i < n; ++i) {
      vec3 d = vec3(rest[i]) - middle;
      d = vec3(d.x * stretch - (i >= n / 2 ? slide : 0.0f), d.y, d.z * stretch);
      const vec3 nudge = vec3(unit(rng), unit(rng), unit(rng)) * 0.01f * radius;
      pos[i] = glm::vec4(middle + turn * d + nudge, 1.0f);
      widest = std::max(widest, glm::length(vec3(pos[i]) - vec3(rest[i])));
    }
    const uint32_t turns = kept.listTurns(), holds = kept.listHolds();
    ASSERT_TRUE(lists.call(pos, prev, triangles, u, rng)) << "call " << call;
    contacts += lists.rebuilt.contacts();
    if (call < 20) turned += kept.listTurns() - turns;
    if (call >= 20 && call < 40) held += kept.listHolds() - holds;
  }
  std::printf("%llu particles in contact a call, travels up to %.2f (%.0f x the lists' travel); lists built %u "
              "times, repaired %u times, kept by the turn %u times and by the clusters %u times in %u calls\n",
              (unsigned long long)(contacts / kCalls), double(widest), double(widest / shaderio::contactTravel(radius)),
              kept.listBuilds(), kept.listRepairs(), kept.listTurns(), kept.listHolds(), kCalls);
  EXPECT_GT(contacts / kCalls, n / 4);
  EXPECT_GT(widest, 100.0f * shaderio::contactTravel(radius));
  EXPECT_GE(turned, 18u);
  EXPECT_GE(held, 15u);
  EXPECT_GE(kept.listBuilds() + kept.listRepairs(), 5u); // the slide
}

TEST(ContactLists, TwoLayersClosingInHaveTheirListsBuiltBeforeTheyMeet) {
  // Two layers of a 24 x 24 grid 100 radii apart, the upper one let down by 6 radii a call until it
  // lies half a radius over the lower, and every particle nudged: each layer travels as one, so
  // clusters next to each other travel alike, and only the spread of the clusters apart
  // (cluster_far_) has the lists built again before a pair comes within the radius
  // (KeptAgainstRebuilt).
  constexpr uint32_t kCalls = 24;
  const float radius = 0.1f, gap = 100.0f * radius;
  const auto [rest, triangles] = stackedLayers(24, 2, gap, glm::vec2(0.0f));
  const uint32_t n = uint32_t(rest.size());
  const shaderio::SimUniforms u = contactUniforms(radius);
  KeptAgainstRebuilt lists;
  const CpuContact& kept = lists.kept;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::vector<glm::vec4> pos = rest, prev;
  uint64_t contacts = 0;
  for (uint32_t call = 0; call < kCalls; ++call) {
    prev = pos;
    const float drop = std::min(6.0f * radius * float(call), gap - 0.5f * radius);
    for (uint32_t i = 0; i < n; ++i)
      pos[i] = rest[i] + glm::vec4(unit(rng), unit(rng), unit(rng), 0.0f) * 0.01f * radius -
               glm::vec4(0.0f, i >= n / 2 ? drop : 0.0f, 0.0f, 0.0f);
    ASSERT_TRUE(lists.call(pos, prev, triangles, u, rng)) << "call " << call;
    contacts += lists.rebuilt.contacts();
  }
  std::printf("%llu particles in contact in all; lists built %u times, repaired %u times, kept by the clusters %u "
              "times in %u calls\n",
              (unsigned long long)contacts, kept.listBuilds(), kept.listRepairs(), kept.listHolds(), kCalls);
  EXPECT_GT(contacts, uint64_t(n));
  EXPECT_GE(kept.listHolds(), 4u);
  EXPECT_GE(kept.listBuilds(), 8u);
}

// A half-space a pair closer than the radius sets particle j of it (slideConstraint).
struct Half {
  glm::uvec4 q;
  NearestPoints c;
  bool edge;
  uint32_t j;
  shaderio::SlideHalf h;
};

// What computeBounds must give, from every particle-triangle and edge-edge pair weighed once
// without lists or a grid, with the half-spaces of the pairs for slide.
struct BruteBounds {
  std::vector<float> bound;
  std::vector<glm::vec4> push;
  std::vector<Half> halves;
  uint32_t pushed = 0; // particles with a push
};

BruteBounds bruteForceBounds(const std::vector<glm::vec4>& pos, const std::vector<glm::uvec4>& triangles,
                             const std::vector<glm::uvec2>& edges, const shaderio::SimUniforms& u) {
  const uint32_t n = uint32_t(pos.size());
  const float radius = u.contact.radius, thickness = radius * SIM_CONTACT_THICKNESS, r2 = radius * radius;
  auto at = [&](uint32_t i) { return vec3(pos[i]); };
  std::vector<float> nearest2(n, r2);
  std::vector<glm::ivec4> sums(n, glm::ivec4(0));
  BruteBounds want;
  auto weigh = [&](glm::uvec4 q, NearestPoints c, bool edge) {
    if (!(c.d2 < r2)) return;
    for (uint32_t j = 0; j < 4; ++j) {
      const shaderio::SlideHalf h =
          shaderio::slideConstraint(at(q.x), at(q.y), at(q.z), at(q.w), c, edge, radius, u.contact.fraction, j);
      if (h.h.w >= 0.0f) want.halves.push_back(Half{q, c, edge, j, h});
    }
    for (uint32_t i : {q.x, q.y, q.z, q.w}) nearest2[i] = std::min(nearest2[i], c.d2);
    if (!(c.d2 < thickness * thickness)) return;
    for (uint32_t j = 0; j < 4; ++j) {
      const glm::ivec3 f = shaderio::contactFixed(
          shaderio::contactPush(pos[q.x], pos[q.y], pos[q.z], pos[q.w], c, thickness, j), u.contact.fixed_units);
      sums[q[j]] += glm::ivec4(f, 1);
    }
  };
  for (uint32_t v = 0; v < n; ++v)
    for (const glm::uvec4& t : triangles)
      if (v != t.x && v != t.y && v != t.z)
        weigh(glm::uvec4(v, t.x, t.y, t.z), shaderio::pointTriangle(at(v), at(t.x), at(t.y), at(t.z)), false);
  for (size_t a = 0; a < edges.size(); ++a)
    for (size_t b = a + 1; b < edges.size(); ++b) {
      const glm::uvec2 e = edges[a], f = edges[b];
      if (e.x != f.x && e.x != f.y && e.y != f.x && e.y != f.y)
        weigh(glm::uvec4(e, f), shaderio::segmentSegment(at(e.x), at(e.y), at(f.x), at(f.y)), true);
    }
  want.bound.resize(n);
  want.push.resize(n);
  for (uint32_t i = 0; i < n; ++i) {
    want.bound[i] = shaderio::slideBound(nearest2[i], radius, u.contact.fraction);
    want.push[i] = glm::vec4(
        shaderio::contactPushWithin(shaderio::contactAverage(sums[i], u.contact.fixed_units), nearest2[i], radius),
        0.0f);
    want.pushed += sums[i].w > 0 ? 1u : 0u;
  }
  return want;
}

// What slide must give for the steps from `pos` to `moved`: what each step passes on to the
// other side of its pairs (a tenth of its excess, weighed by the other particles' parts in the
// pair's nearest point, to those that can move), each step with the mean of what it is passed, its
// excess (the mean, in fixed point) and its share.
struct BruteSlide {
  std::vector<glm::vec4> passed, excess;
  std::vector<float> share;
  uint32_t passing = 0, cut = 0; // half-spaces that pass something on; particles cut
};

BruteSlide bruteForceSlide(const std::vector<Half>& halves, const std::vector<glm::vec4>& pos,
                           const std::vector<glm::vec4>& moved, vec3 frame, const shaderio::SimUniforms& u) {
  const uint32_t n = uint32_t(pos.size());
  auto raw = [&](uint32_t i) { return vec3(moved[i]) - (vec3(pos[i]) + frame); };
  std::vector<glm::ivec4> passed_sums(n, glm::ivec4(0));
  BruteSlide want;
  for (const Half& a : halves) {
    const vec3 e = shaderio::slideExcess(a.h, raw(a.q[a.j]));
    if (e == vec3(0.0f)) continue;
    ++want.passing;
    for (uint32_t k = 0; k < 4; ++k) {
      const bool other = a.edge ? (k < 2) != (a.j < 2) : (k == 0) != (a.j == 0);
      if (!other || !(moved[a.q[k]].w > 0.0f)) continue;
      const float wk = std::abs(a.c.w[int(k)]);
      passed_sums[a.q[k]] +=
          glm::ivec4(shaderio::contactFixed(e * (-SIM_CONTACT_PASS_FRACTION * wk), u.contact.fixed_units), 1);
    }
  }
  want.passed.resize(n);
  for (uint32_t i = 0; i < n; ++i)
    want.passed[i] = glm::vec4(shaderio::contactAverage(passed_sums[i], u.contact.fixed_units), 0.0f);
  auto step = [&](uint32_t i) {
    glm::vec3 x = vec3(moved[i]) + vec3(want.passed[i]);
    x.y = std::max(x.y, std::min(moved[i].y, u.floor_y));
    return x - (vec3(pos[i]) + frame);
  };
  std::vector<glm::ivec4> excess_sums(n, glm::ivec4(0));
  for (const Half& a : halves) {
    const uint32_t i = a.q[a.j];
    const vec3 e = shaderio::slideExcess(a.h, step(i));
    if (e != vec3(0.0f)) excess_sums[i] += glm::ivec4(shaderio::contactFixed(e, u.contact.fixed_units), 1);
  }
  want.excess.resize(n);
  want.share.assign(n, 1.0f);
  for (uint32_t i = 0; i < n; ++i)
    want.excess[i] = glm::vec4(shaderio::contactAverage(excess_sums[i], u.contact.fixed_units), 0.0f);
  for (const Half& a : halves) {
    const uint32_t i = a.q[a.j];
    want.share[i] = std::min(want.share[i], shaderio::slideShare(a.h, step(i) + vec3(want.excess[i])));
  }
  for (uint32_t i = 0; i < n; ++i) want.cut += want.share[i] < 1.0f || excess_sums[i].w > 0 ? 1u : 0u;
  return want;
}

// Three layers of a side x side grid 0.4 radius apart (closer than the thickness: every particle
// pushed), at each call shaken about their rest and one particle in `carried` carried up to half a
// radius in its layer's plane (the lists repaired or built whole): the bounds and pushes are those
// of every particle-triangle and edge-edge pair weighed once, found without a grid, and so are what
// each particle's step is passed by its pairs and the excess and share of that step beyond its pairs'
// half-spaces (slide). A small sheet has a small hash table, where two cells of one box are likelier
// to share a bucket.
void expectBruteForceContact(uint32_t side, uint32_t carried, uint32_t calls) {
  const uint32_t n = 3 * side * side;
  const float radius = 0.1f;
  const auto [rest, triangles] = stackedLayers(side, 3, 0.4f * radius, glm::vec2(0.05f, 0.0f));
  std::vector<glm::uvec2> edges;
  for (const glm::uvec4& t : triangles)
    for (glm::uvec2 e : {glm::uvec2(t.x, t.y), glm::uvec2(t.y, t.z), glm::uvec2(t.z, t.x)})
      edges.push_back(glm::uvec2(std::min(e.x, e.y), std::max(e.x, e.y)));
  std::sort(edges.begin(), edges.end(), [](glm::uvec2 a, glm::uvec2 b) { return a.x != b.x ? a.x < b.x : a.y < b.y; });
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  const shaderio::SimUniforms u = contactUniforms(radius);
  WorkerPool pool(2);
  CpuContact contact(pool, CpuContact::Lists::Repaired);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::vector<glm::vec4> pos = rest, prev;
  std::vector<float> bound;
  std::vector<glm::vec4> push;
  for (uint32_t call = 0; call < calls; ++call) {
    prev = pos;
    for (uint32_t i = 0; i < n; ++i) {
      const float carry = rng() % carried == 0 ? 0.5f * radius : 0.0f;
      pos[i] = rest[i] + glm::vec4(unit(rng) * carry, 0.0f, unit(rng) * carry, 0.0f) +
               glm::vec4(unit(rng), unit(rng), unit(rng), 0.0f) * 0.03f * radius;
    }
    contact.computeBounds(pos, prev, triangles, uint32_t(triangles.size()), u, 1, bound, push);
    // Every particle then stepped up to 0.3 radius (towards the other layers too): the share of each
    // step its pairs' half-spaces keep, and the excess they take out
    std::vector<glm::vec4> moved(n);
    for (uint32_t i = 0; i < n; ++i)
      moved[i] = pos[i] + glm::vec4(unit(rng), unit(rng), unit(rng), 0.0f) * 0.3f * radius;
    std::vector<glm::vec4> passed, excess;
    std::vector<float> share;
    contact.slide(pos, moved, u, passed, excess, share);
    const BruteBounds want = bruteForceBounds(pos, triangles, edges, u);
    const BruteSlide slid = bruteForceSlide(want.halves, pos, moved, contact.frame(), u);
    ASSERT_TRUE(sameBytes(passed, slid.passed)) << side << " x " << side << ", call " << call;
    ASSERT_GT(slid.passing, n / 8) << side << " x " << side << ", call " << call;
    ASSERT_TRUE(sameBytes(excess, slid.excess)) << side << " x " << side << ", call " << call;
    ASSERT_TRUE(sameBytes(share, slid.share)) << side << " x " << side << ", call " << call;
    ASSERT_GT(slid.cut, n / 8) << side << " x " << side << ", call " << call;
    ASSERT_TRUE(sameBytes(bound, want.bound)) << side << " x " << side << ", call " << call;
    ASSERT_TRUE(sameBytes(push, want.push)) << side << " x " << side << ", call " << call;
    ASSERT_GT(want.pushed, n / 2) << side << " x " << side << ", call " << call;
  }
  std::printf("%u x %u x 3: lists built whole %u times, repaired %u times\n", side, side, contact.listBuilds(),
              contact.listRepairs());
  EXPECT_GT(contact.listRepairs(), calls / 3);
}

TEST(ContactLists, TheBoundsAndPushesAreThoseOfABruteForceSearch) {
  expectBruteForceContact(4, 16, 60);
  expectBruteForceContact(10, 30, 40);
}

} // namespace
} // namespace tender::test
