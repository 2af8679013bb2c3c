// exactSqrt and exactDiv with SIM_FLUSH_DENORMALS (a device that can only flush denormals) give
// the bits of the CPU's sqrtss and divss with FTZ and DAZ set: denormal inputs read as zero,
// results below the smallest normal after rounding are zero, those that round up to it are kept.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <glm/glm.hpp>

#include "core/denormal_mode.h"

namespace flushed {
using namespace glm;
using uint = glm::uint;
#define SIM_INEXACT_MATH true
#define SIM_FLUSH_DENORMALS true
#include "exact_math.h"
#undef SIM_INEXACT_MATH
#undef SIM_FLUSH_DENORMALS
} // namespace flushed

namespace {

float fromBits(uint32_t b) { return std::bit_cast<float>(b); }
uint32_t bits(float f) { return std::bit_cast<uint32_t>(f); }
bool same(float a, float b) { return (std::isnan(a) && std::isnan(b)) || bits(a) == bits(b); }

// a / b (or sqrt(a) when `sqrt`) of every pair by the CPU with FTZ and DAZ set. Volatile loads and
// stores keep the arithmetic between the mode switches.
std::vector<float> cpuFlushed(const std::vector<std::pair<float, float>>& pairs, bool sqrt) {
  std::vector<float> out(pairs.size());
  tender::DenormalMode mode(true);
  for (size_t k = 0; k < pairs.size(); ++k) {
    volatile float a = pairs[k].first, b = pairs[k].second;
    volatile float r = sqrt ? std::sqrt(float(a)) : float(a) / float(b);
    out[k] = r;
  }
  return out;
}

uint64_t check(const std::vector<std::pair<float, float>>& pairs, bool sqrt) {
  const std::vector<float> want = cpuFlushed(pairs, sqrt);
  uint64_t bad = 0;
  for (size_t k = 0; k < pairs.size(); ++k) {
    const auto [a, b] = pairs[k];
    const float got = sqrt ? flushed::exactSqrt(a) : flushed::exactDiv(a, b);
    if (!same(got, want[k]) && ++bad <= 5)
      ADD_FAILURE() << std::hexfloat << (sqrt ? "sqrt " : "div ") << a << " " << b << ": " << got << " != " << want[k];
  }
  return bad;
}

} // namespace

TEST(ExactMathFlushed, SqrtOfDenormalsReadsZero) {
  std::vector<std::pair<float, float>> pairs;
  for (uint32_t m = 0; m < 0x800000u; m += 13) {
    pairs.push_back({fromBits(m), 0.0f});
    pairs.push_back({fromBits(0x80000000u | m), 0.0f});
  }
  for (uint32_t m = 0; m < 0x800000u; m += 7) pairs.push_back({fromBits(0x00800000u | m), 0.0f});
  EXPECT_EQ(check(pairs, true), 0u);
}

TEST(ExactMathFlushed, QuotientsAroundTheSmallestNormal) {
  std::vector<std::pair<float, float>> pairs;
  std::mt19937 rng(3);
  for (int k = 0; k < 3'000'000; ++k) {
    // Quotients from a few binades above the smallest normal down to below the smallest denormal,
    // with denormal dividends and divisors among them
    const uint32_t ma = rng() & 0x7FFFFFu, mb = rng() & 0x7FFFFFu, sa = rng() & 0x80000000u;
    const uint32_t ea = rng() % 40, eb = 127 + rng() % 30;
    pairs.push_back({fromBits(sa | ea << 23 | ma), fromBits(eb << 23 | mb)});
    pairs.push_back({fromBits(sa | (1u + rng() % 20) << 23 | ma), fromBits((126u + rng() % 3) << 23 | mb)});
    pairs.push_back({fromBits(sa | (100u + rng() % 50) << 23 | ma), fromBits(mb)}); // by a denormal
  }
  // Exactly at the edge: the smallest normal halved (exact, tiny: zero), and quotients just below
  // it that round up to it (kept)
  pairs.push_back({fromBits(0x00800000u), 2.0f});
  pairs.push_back({fromBits(0x00FFFFFFu), 2.0f});
  pairs.push_back({fromBits(0x00800400u), fromBits(0x3F800000u | 0x400u)});
  for (uint32_t m = 0x7FF000u; m < 0x800000u; ++m)
    pairs.push_back({fromBits(0x00800000u | m), fromBits(0x3F800000u | m)});
  EXPECT_EQ(check(pairs, false), 0u);
}
