// Every SIMD kernel of the CPU solver gives the bits of the scalar reference: the projection (SSE
// and AVX) against solveDistance, the tear test against shouldTear, the collision gather against
// gatherReference, on thousands of random constraints and pairs with awkward values; and whole
// runs with the kernels match runs of the scalar reference alone.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "cpu/cpu_collision.h"
#include "cpu/cpu_runs.h"
#include "cpu/simd_kernels.h"
#include "cpu/worker_pool.h"

using namespace tender;
using namespace shaderio;

namespace {

// Constraints of one colour: constraint k joins particles a[k] and b[k], no particle twice.
struct Constraints {
  std::vector<vec4> pos;
  std::vector<uint32_t> a, b, kind;
  std::vector<float> rest;
};

// A float of magnitude 10^e, e uniform in [lo, hi], with a random sign.
float magnitude(std::mt19937& rng, float lo, float hi) {
  const float e = std::uniform_real_distribution<float>(lo, hi)(rng);
  return (rng() & 1u ? -1.0f : 1.0f) * std::pow(10.0f, e);
}

// `count` constraints with random ends, lengths, rest lengths, inverse masses and kinds, among
// them zero-length and pinned ones, huge and tiny lengths, denormals, and lengths exactly at a
// tear threshold of 2.5.
Constraints randomConstraints(uint32_t count, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  Constraints c;
  c.pos.resize(2 * size_t(count));
  std::vector<uint32_t> order(2 * size_t(count));
  for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), rng); // scattered loads, as in a sheet
  const float weights[] = {1.0f, 1.0f, 1.0f, 0.0f, 0.5f, 2.0f};
  for (uint32_t k = 0; k < count; ++k) {
    const uint32_t ia = order[2 * k], ib = order[2 * k + 1];
    c.a.push_back(ia);
    c.b.push_back(ib);
    c.kind.push_back(rng() % 4u);
    const vec3 pa(10.0f * unit(rng), 10.0f * unit(rng), 10.0f * unit(rng));
    const vec3 dir = normalize(vec3(unit(rng), unit(rng), unit(rng)) + vec3(1e-3f));
    vec3 pb = pa + dir * std::abs(magnitude(rng, -2.0f, 0.5f));
    float rest = std::abs(magnitude(rng, -2.0f, 0.5f));
    vec3 qa = pa;
    switch (rng() % 12u) {
    case 0:
      pb = pa;
      break; // zero length
    case 1:
      pb = pa + dir * std::abs(magnitude(rng, -12.0f, -6.0f));
      break; // near the 1e-9 cut
    case 2:
      pb = pa + dir * std::abs(magnitude(rng, 10.0f, 30.0f));
      break; // huge: dot overflows
    case 3:
      rest = std::abs(magnitude(rng, 10.0f, 30.0f));
      break; // huge rest
    case 4:
      rest = 0.0f;
      break;
    case 5: // denormal coordinates and lengths
      qa = vec3(magnitude(rng, -44.0f, -38.0f), magnitude(rng, -44.0f, -38.0f), 0.0f);
      pb = qa + vec3(magnitude(rng, -44.0f, -38.0f), 0.0f, magnitude(rng, -44.0f, -38.0f));
      rest = std::numeric_limits<float>::denorm_min() * float(rng() % 100u);
      break;
    case 6: // exactly at the tear threshold: length 2.5 x rest
      rest = float(1u + rng() % 8u) * 0.25f;
      pb = pa + vec3(2.5f * rest, 0.0f, 0.0f);
      break;
    case 7:
      rest = std::numeric_limits<float>::denorm_min();
      break;
    default:
      break;
    }
    c.rest.push_back(rest);
    c.pos[ia] = vec4(qa, weights[rng() % 6u]);
    c.pos[ib] = vec4(pb, weights[rng() % 6u]);
  }
  return c;
}

// The reference: solveDistance on constraints [begin, end), as CpuSolver projects them.
void projectScalar(Constraints& c, const float stiffness[4], uint32_t begin, uint32_t end) {
  for (uint32_t k = begin; k < end; ++k) {
    const PairDelta d = solveDistance(c.pos[c.a[k]], c.pos[c.b[k]], c.rest[k], stiffness[c.kind[k]]);
    c.pos[c.a[k]] += vec4(d.da, 0.0f);
    c.pos[c.b[k]] += vec4(d.db, 0.0f);
  }
}

using ProjectKernel = uint32_t (*)(float*, const uint32_t*, const uint32_t*, const float*, const uint32_t*,
                                   const float[4], uint32_t, uint32_t);

// Projects random constraints with the kernel (the reference finishing what it leaves) and with
// the reference alone, from several starts, and expects the same bytes.
void expectKernelMatchesReference(ProjectKernel kernel, uint32_t width) {
  const float stiffness_sets[][4] = {{1.0f, 0.8f, 0.3f, 0.05f}, {0.9f, 1.0f, 1e-30f, 3.0f}};
  uint32_t seed = 1;
  for (const auto& stiffness : stiffness_sets)
    for (uint32_t begin : {0u, 1u, 3u, 6u}) {
      const Constraints start = randomConstraints(4099, seed++);
      const uint32_t end = uint32_t(start.a.size());
      Constraints fast = start, slow = start;
      const uint32_t done = kernel(&fast.pos[0].x, fast.a.data(), fast.b.data(), fast.rest.data(), fast.kind.data(),
                                   stiffness, begin, end);
      EXPECT_LT(end - done, width);
      EXPECT_GE(done - begin, end - begin - (width - 1)); // the kernel did the bulk
      projectScalar(fast, stiffness, done, end);
      projectScalar(slow, stiffness, begin, end);
      ASSERT_EQ(0, std::memcmp(fast.pos.data(), slow.pos.data(), fast.pos.size() * sizeof(vec4)))
          << "seed " << seed - 1 << ", begin " << begin;
    }
}

// A cloud of particles for the collision gather: crowded cells, duplicates, particles on cell
// faces and far away; the adjacency joins each to some of its neighbours and to a few at random.
struct Cloud {
  std::vector<vec4> pos;
  std::vector<uint32_t> adj_offsets, adj_list;
  uint32_t hash_size = 0;
  SimUniforms u{};
};

Cloud randomCloud(uint32_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> box(-1.2f, 1.2f);
  Cloud c;
  const float cell = 0.45f, radius = 0.216f;
  c.u.collision_radius = radius;
  c.u.collision_stiffness = 0.5f;
  c.u.inv_cell = 1.0f / cell;
  c.hash_size = 1;
  while (c.hash_size < 2 * n) c.hash_size *= 2;
  c.u.hash_mask = c.hash_size - 1;
  for (uint32_t i = 0; i < n; ++i) {
    vec3 p(box(rng), box(rng), box(rng));
    switch (rng() % 10u) {
    case 0:
      if (i > 0) p = vec3(c.pos[rng() % i]); // a duplicate: zero distance
      break;
    case 1:
      p.x = cell * float(int(rng() % 6u) - 3);
      break; // on a cell face
    case 2:
      p.y = cell * float(int(rng() % 6u) - 3) + 0.5f * radius * box(rng);
      break;
    case 3:
      p += vec3(900.0f, -700.0f, 650.0f);
      break; // beyond 1024 cells: the kernel is unsure of its side
    default:
      break;
    }
    c.pos.push_back(vec4(p, 1.0f));
  }
  // Adjacency: of the particles within two radii, about one in three; and a few at random.
  c.adj_offsets.push_back(0);
  for (uint32_t i = 0; i < n; ++i) {
    std::vector<uint32_t> adj;
    for (uint32_t j = 0; j < n; ++j) {
      const vec3 d = vec3(c.pos[i]) - vec3(c.pos[j]);
      if (j != i && dot(d, d) < 4.0f * radius * radius && rng() % 3u == 0) adj.push_back(j);
    }
    for (uint32_t extra = rng() % 4u; extra > 0; --extra) adj.push_back(rng() % n);
    if (rng() % 8u == 0) adj.clear(); // no neighbours at all
    std::sort(adj.begin(), adj.end());
    adj.erase(std::unique(adj.begin(), adj.end()), adj.end());
    c.adj_list.insert(c.adj_list.end(), adj.begin(), adj.end());
    c.adj_offsets.push_back(uint32_t(c.adj_list.size()));
  }
  return c;
}

using test::sameBytes;

} // namespace

TEST(SimdKernels, SseProjectionMatchesSolveDistance) {
  if (!simd::kBuilt) GTEST_SKIP() << "no SSE kernels in this build";
  expectKernelMatchesReference(simd::project4, 4);
}

TEST(SimdKernels, AvxProjectionMatchesSolveDistance) {
  if (!simd::hasAvx()) GTEST_SKIP() << "no AVX kernel in this build or on this CPU";
  expectKernelMatchesReference(simd::project8, 8);
  expectKernelMatchesReference(simd::project, 4); // AVX, then SSE on what it leaves
}

// The reference of the shorten stage on constraints [begin, end), as shortenConstraint does it.
void shortenScalar(Constraints& c, float reach, float tear_factor, uint32_t begin, uint32_t end) {
  for (uint32_t k = begin; k < end; ++k) {
    const vec4 pa = c.pos[c.a[k]], pb = c.pos[c.b[k]];
    if (c.kind[k] != SIM_KIND_STRUCTURAL || shouldTear(pa, pb, c.rest[k], SIM_KIND_STRUCTURAL, tear_factor, 0xFu))
      continue;
    const PairDelta d = shortenEdge(pa, pb, reach);
    c.pos[c.a[k]] = pa + vec4(d.da, 0.0f);
    c.pos[c.b[k]] = pb + vec4(d.db, 0.0f);
  }
}

TEST(SimdKernels, AvxShortenMatchesShortenConstraint) {
  if (!simd::hasAvx()) GTEST_SKIP() << "no AVX kernel in this build or on this CPU";
  uint32_t seed = 200, moved = 0;
  for (const float reach : {1.0f, 0.05f, 1e-30f})
    for (const float tear_factor : {0.0f, 2.5f})
      for (uint32_t begin : {0u, 3u}) {
        const Constraints start = randomConstraints(4099, seed++);
        const uint32_t end = uint32_t(start.a.size());
        Constraints fast = start, slow = start;
        const uint32_t done = simd::shorten(&fast.pos[0].x, fast.a.data(), fast.b.data(), fast.rest.data(),
                                            fast.kind.data(), reach, tear_factor, tear_factor > 0.0f, begin, end);
        EXPECT_LT(end - done, 8u);
        shortenScalar(fast, reach, tear_factor, done, end);
        shortenScalar(slow, reach, tear_factor, begin, end);
        ASSERT_EQ(0, std::memcmp(fast.pos.data(), slow.pos.data(), fast.pos.size() * sizeof(vec4)))
            << "reach " << reach << ", tear factor " << tear_factor << ", begin " << begin;
        for (size_t i = 0; i < start.pos.size(); ++i) moved += start.pos[i] != slow.pos[i];
      }
  EXPECT_GT(moved, 5000u); // the edges really move (a quarter are structural)
}

TEST(SimdKernels, TearTestMatchesShouldTear) {
  if (!simd::kBuilt) GTEST_SKIP() << "no SSE kernels in this build";
  uint32_t tearing = 0, seed = 100;
  for (float factor : {2.5f, 1.0f, 0.5f, 1e-30f}) {
    const Constraints c = randomConstraints(4099, seed++);
    const uint32_t count = uint32_t(c.a.size());
    std::vector<uint8_t> fast(count, 0), slow(count, 0);
    for (uint32_t k = 0; k < count; ++k)
      slow[k] = shouldTear(c.pos[c.a[k]], c.pos[c.b[k]], c.rest[k], c.kind[k], factor, 0xFu) ? 1u : 0u;
    // Groups of 64, then whatever multiple of 4 is left; the last constraints as the solver does.
    uint32_t k = 0;
    for (uint32_t n; (n = std::min(64u, (count - k) & ~3u)) > 0; k += n) {
      const uint64_t over = simd::stretched(&c.pos[0].x, c.a.data(), c.b.data(), c.rest.data(), factor, k, n);
      EXPECT_EQ(over >> (n - 1) >> 1, 0u) << "a lane beyond the group at " << k;
      for (uint32_t l = 0; l < n; ++l) fast[k + l] = (over >> l) & 1u;
    }
    for (; k < count; ++k) fast[k] = slow[k];
    EXPECT_TRUE(sameBytes(fast, slow)) << "tear factor " << factor;
    for (uint8_t t : slow) tearing += t;
  }
  EXPECT_GT(tearing, 1000u); // the test really tears
}

TEST(SimdKernels, CollisionGatherMatchesReference) {
  if (!simd::kBuilt) GTEST_SKIP() << "no SSE kernels in this build";
  WorkerPool pool(1);
  for (uint32_t seed : {1u, 2u, 3u}) {
    const Cloud c = randomCloud(3000, seed);
    CpuCollision fast(pool, true, true), slow(pool, false, true);
    fast.upload(c.adj_offsets, c.adj_list, c.hash_size, Grain{});
    slow.upload(c.adj_offsets, c.adj_list, c.hash_size, Grain{});
    fast.buildHash(c.u, c.pos.data());
    slow.buildHash(c.u, c.pos.data());
    ASSERT_EQ(fast.cellParticles(), slow.cellParticles());
    const float radius = c.u.collision_radius, skin = candidateSkin(radius, c.u.inv_cell);
    ASSERT_GT(skin, 0.0f);
    // Within the radius; then within radius + skin, building the candidate lists.
    bool fits = true;
    for (const bool build : {false, true}) {
      const float search = build ? radius + skin : radius;
      fits = slow.gather(c.u, search, build);
      EXPECT_EQ(fast.gather(c.u, search, build), fits);
      EXPECT_TRUE(sameBytes(fast.slotDeltas(), slow.slotDeltas())) << "seed " << seed << ", build " << build;
      EXPECT_TRUE(sameBytes(fast.candidates(), slow.candidates())) << "seed " << seed;
      EXPECT_TRUE(sameBytes(fast.candidateBase(), slow.candidateBase())) << "seed " << seed;
    }
    // The cloud is crowded enough to matter: most particles are pushed, lists fill and some overflow.
    uint32_t pushed = 0, listed = 0;
    for (uint32_t k = 0; k < 3000; ++k) {
      pushed += slow.slotDeltas()[k] != vec4(0.0f) ? 1u : 0u;
      listed += slow.candidates()[size_t(SIM_CANDIDATE_STRIDE) * k];
    }
    EXPECT_GT(pushed, 1500u);
    EXPECT_GT(listed, 3000u);
    EXPECT_FALSE(fits);
  }
}

namespace {

constexpr CpuOptions kScalarOne{.threads = 1, .min_chunk = 1, .simd = false};
constexpr CpuOptions kScalarTwo{.threads = 2, .min_chunk = 1, .simd = false};
constexpr CpuOptions kSimdOne{.threads = 1, .min_chunk = 1, .simd = true};
constexpr CpuOptions kSimdTwo{.threads = 2, .min_chunk = 1, .simd = true};

} // namespace

// The `tender` runs are the seeds' cloth, its contact off; contact with and without SIMD: the
// crumple runs

TEST(SimdSimulation, TearingYankIsIdenticalWithoutSimd) {
  // (it tears in its second tick; the last ticks run let go)
  const std::string yank = "0 grab particle 1535\n1 move 4 -4 6\n12 release\n";
  EXPECT_FALSE(CpuSolver(kScalarOne).usesSimd());
  EXPECT_EQ(CpuSolver(kSimdOne).usesSimd(), simd::kBuilt);
  // Under ThreadSanitizer the two threaded runs alone, each judged by it; elsewhere against the
  // scalar run on one thread
  const SimState simd_two = test::runCpu(test::cloth(), yank, 20, kSimdTwo);
  const SimState scalar_two = test::runCpu(test::cloth(), yank, 20, kScalarTwo);
  EXPECT_GT(test::tornCount(simd_two), 0u); // the run tears and compacts
  test::expectIdentical(simd_two, scalar_two);
  if (!test::kComparesThreadCounts) return;
  const SimState reference = test::runCpu(test::cloth(), yank, 20, kScalarOne);
  test::expectIdentical(reference, test::runCpu(test::cloth(), yank, 20, kSimdOne));
  test::expectIdentical(reference, simd_two);
}

TEST(SimdSimulation, CrumpleTossIsIdenticalWithoutSimd) {
  const std::string toss = "0 grab particle 100\n1 move 1 2 3\n10 release\n";
  const SimState reference = test::runCpu("crumple", {"cols=13", "rows=19"}, toss, 20, kScalarOne);
  test::expectIdentical(reference, test::runCpu("crumple", {"cols=13", "rows=19"}, toss, 20, kSimdOne));
  test::expectIdentical(reference, test::runCpu("crumple", {"cols=13", "rows=19"}, toss, 20, kSimdTwo));
  test::expectIdentical(reference, test::runCpu("crumple", {"cols=13", "rows=19"}, toss, 20, kScalarTwo));
}

TEST(SimdSimulation, TheShortenStageIsIdenticalWithoutSimd) {
  // Sheets no pin holds, so the shorten stage runs once the grab lets go: a crumple sheet tossed,
  // and a tender sheet with the limit yanked hard enough to tear (edges at their tear length are
  // left to tear) and let go
  const std::string toss = "0 grab particle 100\n1 move 1 2 3\n10 release\n";
  const std::vector<std::string> crumple = {"cols=13", "rows=19", "pins=none"};
  const SimState reference = test::runCpu("crumple", crumple, toss, 20, kScalarOne);
  test::expectIdentical(reference, test::runCpu("crumple", crumple, toss, 20, kSimdOne));
  test::expectIdentical(reference, test::runCpu("crumple", crumple, toss, 20, kSimdTwo));
  const std::string yank = "0 grab particle 1535\n1 move 4 -4 6\n12 release\n";
  const std::vector<std::string> tender = {"pins=none", "stretch_limit=1.01", "tear_factor=1.5"};
  const SimState torn = test::runCpu("tender", tender, yank, 30, kScalarOne);
  EXPECT_GT(test::tornCount(torn), 0u);
  test::expectIdentical(torn, test::runCpu("tender", tender, yank, 30, kSimdOne));
  test::expectIdentical(torn, test::runCpu("tender", tender, yank, 30, kSimdTwo));
}
