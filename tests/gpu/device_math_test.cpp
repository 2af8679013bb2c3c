// exactSqrt and exactDiv as the device runs them (shader math_check.comp) under the emulated
// inexact device: the CPU's correctly rounded bits for every significand of sqrt and millions of
// quotients; without the correction the same device disagrees.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <random>

#include "core/denormal_mode.h"
#include "gpu/sim_pipeline.h"
#include "gpu_test_env.h"

using namespace tender;

namespace {

bool same(uint32_t a, uint32_t b) {
  const float fa = std::bit_cast<float>(a), fb = std::bit_cast<float>(b);
  return a == b || (std::isnan(fa) && std::isnan(fb));
}

// Cases whose device results differ from the CPU's sqrt and divide, computed here with denormals
// flushed (FTZ and DAZ), as the CPU reference computes; the first few are reported.
uint64_t mismatches(const std::vector<gpu::MathCase>& cases) {
  uint64_t bad = 0;
  const DenormalMode mode(true);
  for (const gpu::MathCase& c : cases) {
    // Volatile loads and stores keep the arithmetic inside the mode
    volatile float va = std::bit_cast<float>(c.a), vb = std::bit_cast<float>(c.b);
    const float a = va, b = vb;
    volatile float vsqrt = std::sqrt(a), vdiv = a / b;
    const uint32_t want_sqrt = std::bit_cast<uint32_t>(float(vsqrt)), want_div = std::bit_cast<uint32_t>(float(vdiv));
    if ((!same(c.sqrt_a, want_sqrt) || !same(c.a_over_b, want_div)) && ++bad <= 5)
      ADD_FAILURE() << std::hex << "a " << c.a << " b " << c.b << ": sqrt " << c.sqrt_a << " (want " << want_sqrt
                    << "), a / b " << c.a_over_b << " (want " << want_div << ")";
  }
  return bad;
}

std::vector<gpu::MathCase> mathCases() {
  std::vector<gpu::MathCase> cases;
  // sqrt: every significand at both exponent parities, and the denormals in steps
  for (uint32_t m = 0; m < (1u << 23); ++m) {
    gpu::MathCase c;
    c.a = 0x3F800000u | m; // [1, 2)
    c.b = 0x40000000u | m; // [2, 4)
    cases.push_back(c);
  }
  for (uint32_t m = 1; m < (1u << 23); m += 97) cases.push_back({m, 0x3F800000u | (m * 13u & 0x7FFFFFu), 0, 0});
  std::mt19937_64 rng(11);
  for (int k = 0; k < 2'000'000; ++k) {
    const uint64_t r = rng();
    cases.push_back({uint32_t(r) & 0xFF7FFFFFu, uint32_t(r >> 32) & 0xFF7FFFFFu, 0, 0});
  }
  return cases;
}

} // namespace

using DeviceMath = test::GpuTest;

TEST_F(DeviceMath, ExactSqrtAndDivideOnAnInexactDeviceGiveTheCpuBits) {
  std::vector<gpu::MathCase> cases = mathCases();
  gpu::runDeviceMath(ctx(), cases, {true, true});
  EXPECT_EQ(mismatches(cases), 0u) << "of " << cases.size() << " cases";
}

TEST_F(DeviceMath, WithoutTheCorrectionTheInexactDeviceDisagrees) {
  std::vector<gpu::MathCase> cases;
  for (uint32_t m = 0; m < 10000; ++m) cases.push_back({0x3F800000u | m * 797u, 0x3FC00000u | m * 31u, 0, 0});
  gpu::runDeviceMath(ctx(), cases, {true, false});
  int wrong = 0;
  for (const gpu::MathCase& c : cases) {
    const float a = std::bit_cast<float>(c.a), b = std::bit_cast<float>(c.b);
    wrong += c.sqrt_a != std::bit_cast<uint32_t>(std::sqrt(a)) || c.a_over_b != std::bit_cast<uint32_t>(a / b);
  }
  EXPECT_GT(wrong, 5000);
}

// The CPU reference flushes denormals (FTZ and DAZ) and so do the shaders on every device, by the
// device's float controls, by their own code, or on a CPU device by the host's FTZ and DAZ in its
// threads (gpu::simFloatRules): products and sums with denormal results, and denormal inputs, which
// read as zero (a denormal times 2^50..2^100 is a normal number where they are kept). NVIDIA's
// driver, which can be asked neither to keep nor to flush them, kept them in this shader and flushed
// one in the projection pass before the shaders flushed them.
TEST_F(DeviceMath, PlainArithmeticTreatsDenormalsLikeTheCpu) {
  std::vector<gpu::MathCase> cases;
  const uint32_t tiny = 0x1E3CE508u; // 1e-20: its square is a denormal
  cases.push_back({tiny, tiny, 0, 0});
  cases.push_back({0x00800000u, 0x3F000000u, 0, 0}); // the smallest normal / 2
  cases.push_back({0x00000001u, 0x40000000u, 0, 0}); // the smallest denormal x 2
  cases.push_back({0x00400000u, 0x80000100u, 0, 0}); // denormal + a negative denormal
  std::mt19937 rng(5);
  for (int k = 0; k < 4096; ++k) {
    const uint32_t a = uint32_t(rng()) & 0x807FFFFFu, b = (uint32_t(rng()) & 0x807FFFFFu) | 0x3F000000u;
    cases.push_back({a, b, 0, 0});
    cases.push_back({a, (uint32_t(rng()) & 0x807FFFFFu) | (177u + uint32_t(rng()) % 50u) << 23, 0, 0});
  }
  gpu::runDeviceMath(ctx(), cases, {}, gpu::MathOp::MulAdd);
  int bad = 0;
  const DenormalMode mode(true);
  for (const gpu::MathCase& c : cases) {
    volatile float va = std::bit_cast<float>(c.a), vb = std::bit_cast<float>(c.b);
    const float a = va, b = vb;
    volatile float vmul = a * b, vadd = a + b;
    const uint32_t want_mul = std::bit_cast<uint32_t>(float(vmul)), want_add = std::bit_cast<uint32_t>(float(vadd));
    if ((c.sqrt_a != want_mul || c.a_over_b != want_add) && ++bad <= 5)
      ADD_FAILURE() << std::hexfloat << "a " << a << " b " << b << ": a * b " << std::bit_cast<float>(c.sqrt_a)
                    << " (want " << a * b << "), a + b " << std::bit_cast<float>(c.a_over_b) << " (want " << a + b
                    << ")";
  }
  EXPECT_EQ(bad, 0) << "the device does not treat denormals as asked (tender devices: " << ctx().info().name << ")";
}

// Lavapipe cannot be asked to flush denormals, but the threads it starts for a context inherit the
// host's FTZ and DAZ (VulkanContext::create sets them meanwhile), so its shaders need no flush of
// their own, which cost a quarter of a kernel's run and of its compile there: the probe proves it.
TEST_F(DeviceMath, ACpuDeviceFlushesWithTheHostsFtzAndDaz) {
  if (ctx().properties().deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU) GTEST_SKIP() << "not a CPU device";
  if (ctx().floatControls().denorm_flush) GTEST_SKIP() << "the device can be asked to flush them";
  EXPECT_EQ(gpu::simFloatRules(ctx()).denormals, gpu::Denormals::FlushByHost);
}

// The shaders' exactSqrt and exactDiv, which flush denormals (SIM_FLUSH_DENORMALS) on every device, give the CPU's bits
// with FTZ and DAZ set: denormal inputs, tiny quotients, and quotients that round up to the smallest normal.
TEST_F(DeviceMath, FlushingExactMathGivesTheCpuBitsWithFtzAndDaz) {
  std::vector<gpu::MathCase> cases;
  std::mt19937 rng(9);
  for (uint32_t m = 0; m < 0x800000u; m += 101) cases.push_back({m, 0x3F800000u | (m * 7u & 0x7FFFFFu), 0, 0});
  for (int k = 0; k < 400'000; ++k) {
    const uint32_t ma = uint32_t(rng()) & 0x7FFFFFu, mb = uint32_t(rng()) & 0x7FFFFFu;
    cases.push_back({(1u + uint32_t(rng()) % 20u) << 23 | ma, (126u + uint32_t(rng()) % 3u) << 23 | mb, 0, 0});
    cases.push_back({uint32_t(rng()) % 40u << 23 | ma, (127u + uint32_t(rng()) % 30u) << 23 | mb, 0, 0});
  }
  for (uint32_t m = 0x7FF000u; m < 0x800000u; ++m) cases.push_back({0x00800000u | m, 0x3F800000u | m, 0, 0});
  gpu::MathSwitches math;
  math.inexact = true;
  gpu::runDeviceMath(ctx(), cases, math);
  EXPECT_EQ(mismatches(cases), 0u) << "of " << cases.size() << " cases";
}
