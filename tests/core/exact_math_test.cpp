// exactSqrt and exactDiv (shaders/shared/exact_math.h) give the bits of the CPU's correctly
// rounded sqrt and divide, here started from a deliberately inexact device (off by -3..+3 ULP):
// every significand of sqrt at both exponent parities, every denormal, and many millions of
// quotients across the whole range, with the half-way and carry cases.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <random>

#include <glm/glm.hpp>

namespace emulated {
using namespace glm;
using uint = glm::uint;
#define SIM_INEXACT_MATH true
#include "exact_math.h"
#undef SIM_INEXACT_MATH
} // namespace emulated

namespace {

float fromBits(uint32_t b) { return std::bit_cast<float>(b); }
uint32_t bits(float f) { return std::bit_cast<uint32_t>(f); }

/// Same bits, or both NaN (a NaN's payload is not part of the contract).
bool same(float a, float b) { return (std::isnan(a) && std::isnan(b)) || bits(a) == bits(b); }

/// Checks exactSqrt(x) against std::sqrt(x) for x with magnitude bits in [first, last); returns the
/// number of mismatches and reports the first few.
uint64_t checkSqrtRange(uint32_t first, uint32_t last, uint32_t sign = 0u) {
  uint64_t bad = 0;
  for (uint32_t b = first; b < last; ++b) {
    const float x = fromBits(sign | b);
    const float got = emulated::exactSqrt(x), want = std::sqrt(x);
    if (!same(got, want) && ++bad <= 5)
      ADD_FAILURE() << std::hexfloat << "sqrt(" << x << "): " << got << " != " << want;
  }
  return bad;
}

uint64_t checkDiv(float a, float b) {
  const float got = emulated::exactDiv(a, b), want = a / b;
  if (same(got, want)) return 0;
  ADD_FAILURE() << std::hexfloat << a << " / " << b << ": " << got << " != " << want;
  return 1;
}

} // namespace

TEST(ExactMath, TheEmulatedDeviceIsInexactBothWays) {
  // Without the emulation being wrong, the tests below would prove nothing.
  int seen[7] = {};
  std::mt19937 rng(1);
  for (int k = 0; k < 100000; ++k) {
    const float x = std::uniform_real_distribution<float>(1.0f, 4.0f)(rng);
    const int off = int(bits(emulated::deviceSqrt(x))) - int(bits(std::sqrt(x)));
    ASSERT_GE(off, -3);
    ASSERT_LE(off, 3);
    ++seen[off + 3];
    const float y = std::uniform_real_distribution<float>(1.0f, 2.0f)(rng);
    const int doff = int(bits(emulated::deviceDiv(x, y))) - int(bits(x / y));
    ASSERT_GE(doff, -3);
    ASSERT_LE(doff, 3);
  }
  for (int s : seen) EXPECT_GT(s, 1000);
}

TEST(ExactMath, SqrtOfEverySignificandAtBothExponentParities) {
  // The correction depends only on the significand and the parity of the exponent: exponents
  // 0 and 1 cover every case; the lowest and highest exponents check the exponent arithmetic.
  for (uint32_t field : {127u, 128u, 1u, 2u, 253u, 254u})
    EXPECT_EQ(checkSqrtRange(field << 23, (field + 1) << 23), 0u) << "exponent field " << field;
}

TEST(ExactMath, SqrtOfEveryDenormalAndTheSpecials) {
  EXPECT_EQ(checkSqrtRange(0u, 0x800000u), 0u);
  for (float x : {0.0f, -0.0f, INFINITY, -INFINITY, NAN, -1.0f, -1e-45f, 1.0f, 4.0f, 0.25f, 3.4028235e38f})
    EXPECT_TRUE(same(emulated::exactSqrt(x), std::sqrt(x))) << x;
}

TEST(ExactMath, SqrtOfExactSquares) {
  for (uint32_t s = 1; s < (1u << 12); ++s) {
    const float x = float(s) * float(s);
    EXPECT_EQ(bits(emulated::exactSqrt(x)), bits(float(s)));
    EXPECT_EQ(bits(emulated::exactSqrt(x * 0x1p-140f)), bits(float(s) * 0x1p-70f));
  }
}

TEST(ExactMath, DivOfManyMillionsOfPairsOverTheWholeRange) {
  std::mt19937_64 rng(20261123);
  uint64_t bad = 0;
  for (int k = 0; k < 12'000'000 && bad < 5; ++k) {
    const uint64_t r = rng();
    // Any magnitude bits (denormals, huge, tiny), any sign; a third of the pairs share an exponent
    // field so that their quotient lies near 1 and the significands decide everything
    uint32_t a = uint32_t(r) & 0x7F7FFFFFu, b = uint32_t(r >> 32) & 0x7F7FFFFFu;
    if (k % 3 == 0) b = (b & 0x807FFFFFu) | (a & 0x7F800000u);
    a |= uint32_t(r >> 7) & 0x80000000u;
    bad += checkDiv(fromBits(a), fromBits(b));
  }
  EXPECT_EQ(bad, 0u);
}

TEST(ExactMath, DivHalfwayCasesCarriesAndSpecials) {
  uint64_t bad = 0;
  // Ties: a denormal halved rounds half-way to even
  for (uint32_t m = 1; m < 0x800000u && bad < 5; m += 1)
    bad += checkDiv(fromBits(m), 2.0f) + checkDiv(fromBits(m), 4.0f);
  // Results at the edges: overflow to infinity, underflow into denormals and to zero, the carry
  // of a rounded-up significand into the exponent
  std::mt19937 rng(7);
  for (int k = 0; k < 2'000'000 && bad < 5; ++k) {
    const uint32_t ma = rng() & 0x7FFFFFu, mb = rng() & 0x7FFFFFu;
    const uint32_t ea = 1 + rng() % 254, shift = rng() % 40;
    const float a = fromBits(ea << 23 | ma);
    bad += checkDiv(a, fromBits(std::min(254u, ea + 24 + shift % 8) << 23 | mb));               // tiny results
    bad += checkDiv(a, fromBits(uint32_t(std::max(1, int(ea) - 127 - int(shift))) << 23 | mb)); // huge
    bad += checkDiv(fromBits(ea << 23 | 0x7FFFFFu), fromBits(ea << 23 | mb));                   // near 2
    bad += checkDiv(fromBits(ea << 23 | ma), fromBits(ea << 23 | 0x7FFFFFu));                   // near 1/2
  }
  const float specials[] = {0.0f,  -0.0f,  INFINITY, -INFINITY,     NAN,           1.0f,
                            -3.0f, 1e-45f, -1e-40f,  3.4028235e38f, 1.1754944e-38f};
  for (float a : specials)
    for (float b : specials) bad += checkDiv(a, b);
  EXPECT_EQ(bad, 0u);
}

TEST(ExactMath, WithoutTheCorrectionTheEmulatedDeviceIsWrong) {
  // What the correction is for: the raw emulated device disagrees with the CPU on most inputs.
  int wrong = 0;
  for (uint32_t m = 0; m < 10000; ++m) {
    const float x = fromBits(0x3F800000u | m * 797u);
    wrong += bits(emulated::deviceSqrt(x)) != bits(std::sqrt(x));
  }
  EXPECT_GT(wrong, 5000);
}
