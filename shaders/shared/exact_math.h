// Arithmetic with the same bits on every device, shared by GLSL and C++ (included by sim_types.h).
//
// Vulkan makes add, subtract and multiply correctly rounded (when not fused: every float operation
// of the simulation's SPIR-V carries NoContraction, see shaders/spirv/spirv_rules.cpp), but lets `sqrt`
// be off by about 3 ULP and `x / y` by 2.5 ULP, and leaves the order inside dot(), cross(),
// length() and mix() to the implementation. So the simulation writes dot products out, and its
// square roots and divisions are exactSqrt and exactDiv: the device's approximation, corrected to
// the correctly rounded result by an exact integer remainder. The C++ reference uses the CPU's
// correctly rounded sqrtss/divss, which give the same bits (tests/core/exact_math_test.cpp proves
// it over every significand of sqrt and many millions of quotients).
//
// Before including this file a GLSL shader may define SIM_INEXACT_MATH, SIM_CORRECT_MATH and
// SIM_FLUSH_DENORMALS (sim_common.glsl makes them specialization constants): the first replaces
// the device's sqrt and divide by deliberately inexact ones (off by -3..+3 ULP, like a real GPU's),
// the second, when false, returns the approximation uncorrected (to show what the correction is
// for), the third makes them treat denormals as the CPU does with FTZ and DAZ set (on a device
// that can only flush denormals, where the CPU reference flushes too): a denormal input reads as
// zero, and a result below the smallest normal after rounding is zero.
#ifndef SIM_EXACT_MATH_H
#define SIM_EXACT_MATH_H
#include "prelude.h"

#ifndef SIM_INEXACT_MATH
#define SIM_INEXACT_MATH false
#endif
#ifndef SIM_CORRECT_MATH
#define SIM_CORRECT_MATH true
#endif
#ifndef SIM_FLUSH_DENORMALS
#define SIM_FLUSH_DENORMALS false
#endif

/// a . b in a fixed order: (ax bx + ay by) + az bz.
SIM_INLINE float dot3(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

/// a x b, each component one difference of two products.
SIM_INLINE vec3 cross3(vec3 a, vec3 b) {
  return vec3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}

/// Linear blend a (1 - t) + b t, per component.
SIM_INLINE vec3 blend3(vec3 a, vec3 b, float t) { return a * (1.0f - t) + b * t; }

/// An offset of -3..+3 units in the last place, from a hash of `h` (the emulated inexact device).
SIM_INLINE uint inexactOffset(uint h) {
  h ^= h >> 16u;
  h *= 0x7FEB352Du;
  h ^= h >> 15u;
  h *= 0x846CA68Bu;
  h ^= h >> 16u;
  return h % 7u - 3u;
}

// What follows is written without an early return or a branch: its special cases (zero,
// infinity, NaN, a denormal, an overflow) are selects. A shader inlines it at every divide and
// square root, and there each return or branch became control flow that the driver's compiler had
// to restructure: on lavapipe it took twice as long to build the largest kernels, for the same
// bits. GLSL compilers make `c ? a : b` a branch unless a and b are plain values, so the choices
// go through pickU, pickI and pickF, and the conditions are named before they are combined.

/// c ? a : b, as a select.
SIM_INLINE uint pickU(bool c, uint a, uint b) { return c ? a : b; }
SIM_INLINE int pickI(bool c, int a, int b) { return c ? a : b; }
SIM_INLINE float pickF(bool c, float a, float b) { return c ? a : b; }

/// The device's square root of x >= 0, made inexact when SIM_INEXACT_MATH.
SIM_INLINE float deviceSqrt(float x) {
  float r = sqrt(x);
  bool positive = r > 0.0f, finite = r < 3.0e38f;
  float off = uintBitsToFloat(floatBitsToUint(r) + inexactOffset(floatBitsToUint(x)));
  return pickF(SIM_INEXACT_MATH && positive && finite, off, r);
}

/// The device's quotient a / b, made inexact when SIM_INEXACT_MATH.
SIM_INLINE float deviceDiv(float a, float b) {
  float q = a / b;
  float m = abs(q);
  bool large = m > 1.0e-37f, finite = m < 3.0e38f;
  float off =
      uintBitsToFloat(floatBitsToUint(q) + inexactOffset(floatBitsToUint(a) * 0x9E3779B9u ^ floatBitsToUint(b)));
  return pickF(SIM_INEXACT_MATH && large && finite, off, q);
}

/// The bits of x, a denormal read as zero where denormals are flushed.
SIM_INLINE uint inputBits(float x) {
  uint bits = floatBitsToUint(x);
  bool denormal = (bits & 0x7F800000u) == 0u;
  return pickU(SIM_FLUSH_DENORMALS && denormal, bits & 0x80000000u, bits);
}

/// Significand (x: in [2^23, 2^24)) and unbiased exponent (y) of the finite non-zero float with
/// magnitude bits `bits`; a denormal is normalised (with SIM_FLUSH_DENORMALS the callers have read
/// it as zero, so there is none).
SIM_INLINE ivec2 splitFloat(uint bits) {
  uint field = bits >> 23u;
  bool zero_field = field == 0u;
  bool denormal = !SIM_FLUSH_DENORMALS && zero_field;
  int shift = pickI(denormal, 23 - findMSB(bits), 0);
  uint m = pickU(denormal, bits << uint(shift), (bits & 0x7FFFFFu) | 0x800000u);
  return ivec2(int(m), pickI(denormal, -126 - shift, int(field) - 127));
}

/// The float with sign `sign`, biased exponent `biased` (<= 0: denormal) and significand q in
/// [2^23, 2^24) rounded to nearest even by `above`: the rest beyond q compared with half an ulp (-1
/// below, 0 exactly half, 1 above; `inexact`: anything at all beyond q).
SIM_INLINE float packRounded(uint sign, int biased, uint q, int above, bool inexact) {
  bool beyond_half = above > 0, exactly_half = above == 0, odd = (q & 1u) != 0u;
  bool to_even = exactly_half && odd;
  uint up = pickU(beyond_half || to_even, 1u, 0u);
  // A carry out of the significand moves into the exponent (up to infinity)
  uint normal = (uint(biased - 1) << 23u) + q + up;
  // Flushed (as x86 FTZ) unless it rounds up to the smallest normal (tininess after rounding)
  bool to_smallest = biased == 0, carries = q + up == 0x1000000u;
  uint flushed = pickU(to_smallest && carries, 0x800000u, 0u);
  // Kept: q >> s, rounded on the bits shifted out (past 25 places nothing is left, as q < 2^24)
  uint s = uint(clamp(1 - biased, 1, 25));
  uint m = q >> s;
  bool guard = ((q >> (s - 1u)) & 1u) != 0u, rest = (q & ((1u << (s - 1u)) - 1u)) != 0u, m_odd = (m & 1u) != 0u;
  bool sticky_or_odd = rest || inexact || m_odd;
  uint kept = m + pickU(guard && sticky_or_odd, 1u, 0u);
  uint tiny = pickU(SIM_FLUSH_DENORMALS, flushed, kept);
  bool overflow = biased >= 255, normalised = biased >= 1;
  return uintBitsToFloat(sign | pickU(overflow, 0x7F800000u, pickU(normalised, normal, tiny)));
}

/// Correctly rounded a / b (round to nearest even, denormals kept) on any device.
SIM_INLINE float exactDiv(float a, float b) {
  uint ua = inputBits(a), ub = inputBits(b);
  uint sign = (ua ^ ub) & 0x80000000u;
  uint xa = ua & 0x7FFFFFFFu, xb = ub & 0x7FFFFFFFu;
  // Zero, infinity and NaN give their answer at the end; the arithmetic runs on 1 / 1 instead
  const uint kInf = 0x7F800000u;
  bool nan_a = xa > kInf, nan_b = xb > kInf, inf_a = xa == kInf, inf_b = xb == kInf;
  bool zero_a = xa == 0u, zero_b = xb == 0u;
  bool both_inf = inf_a && inf_b, both_zero = zero_a && zero_b;
  bool nan = nan_a || nan_b || both_inf || both_zero;
  bool inf = inf_a || zero_b;
  bool special = nan || inf || zero_a || inf_b;
  uint answer = pickU(nan, 0x7FC00000u, pickU(inf, sign | kInf, sign));
  ivec2 fa = splitFloat(pickU(special, 0x3F800000u, xa)), fb = splitFloat(pickU(special, 0x3F800000u, xb));
  uint ma = uint(fa.x), mb = uint(fb.x);
  // q = floor(ma 2^shift / mb) in [2^23, 2^24); the result is q 2^(e - 23)
  bool ge = ma >= mb;
  uint shift = pickU(ge, 23u, 24u);
  int e = fa.y - fb.y - pickI(ge, 0, 1);
  // Start from the device's quotient of the significands (both in [1, 2), so it is within a few
  // ULP), then step to the floor: the remainder ma 2^shift - q mb is exact modulo 2^32 and small.
  float approx =
      deviceDiv(uintBitsToFloat(0x3F800000u | (ma & 0x7FFFFFu)), uintBitsToFloat(0x3F800000u | (mb & 0x7FFFFFu)));
  uint q = clamp(uint(approx * pickF(ge, 8388608.0f, 16777216.0f)), 0x800000u, 0xFFFFFFu);
  int r = int((ma << shift) - q * mb);
  // q is off by a few units: an estimate of floor(r / mb) (within one of it: |r / mb| <= 5, and
  // 1.5 - x / 2 is within 12 % of 1 / x on [1, 2), so no second division) and one last step
  float inv_mb = (1.5f - 0.5f * uintBitsToFloat(0x3F800000u | (mb & 0x7FFFFFu))) * 1.1920929e-7f;
  int d = int(floor(float(r) * inv_mb));
  q += uint(d);
  r -= d * int(mb);
  bool low = r < 0, high = r >= int(mb);
  int last = pickI(low, -1, pickI(high, 1, 0));
  q += uint(last);
  r -= last * int(mb);
  uint twice = 2u * uint(r);
  bool over = twice > mb, tie = twice == mb;
  float result = packRounded(sign, e + 127, q, pickI(over, 1, pickI(tie, 0, -1)), r != 0);
  return pickF(SIM_CORRECT_MATH, pickF(special, uintBitsToFloat(answer), result), deviceDiv(a, b));
}

/// Correctly rounded sqrt(x) (round to nearest even, denormals kept) on any device.
SIM_INLINE float exactSqrt(float x) {
  uint ux = inputBits(x);
  // Zero and infinity are their own roots; a NaN or a negative number has none. The arithmetic
  // runs on 1 instead.
  uint magnitude = ux & 0x7FFFFFFFu;
  bool zero = magnitude == 0u, inf = ux == 0x7F800000u, none = ux > 0x7F800000u;
  bool itself = zero || inf;
  bool special = itself || none;
  uint answer = pickU(itself, ux, 0x7FC00000u);
  ivec2 f = splitFloat(pickU(special, 0x3F800000u, ux));
  uint m = uint(f.x);
  // x = m 2^(e - 23); with an even exponent left over, sqrt(x) = sqrt(N) 2^(half - 23) where
  // N = m 2^(23 or 24) lies in [2^46, 2^48) and s = floor(sqrt(N)) in [2^23, 2^24)
  bool odd = (f.y & 1) != 0;
  int half_exp = (f.y - pickI(odd, 1, 0)) / 2;
  float scaled = uintBitsToFloat(0x3F800000u | (m & 0x7FFFFFu)) * pickF(odd, 2.0f, 1.0f); // N / 2^46
  uint s = clamp(uint(deviceSqrt(scaled) * 8388608.0f), 0x800000u, 0xFFFFFFu);
  // r = N - s^2, exact modulo 2^32 and small; s is the floor when 0 <= r <= 2s
  uint n = m << pickU(odd, 24u, 23u);
  int r = int(n - s * s);
  // s is off by a few units: an estimate of the step r / 2s (within one of it: |r / 2s| <= 5, and
  // 1.5 - x / 2 is within 12 % of 1 / x on [1, 2), so no division), then one last step: below the
  // floor, s - 1 leaves r + 2s - 1; above it, s + 1 leaves r - 2s - 1
  float inv_2s = (1.5f - 0.5f * float(s) * 1.1920929e-7f) * 5.9604645e-8f;
  s += uint(int(floor(float(r) * inv_2s)));
  r = int(n - s * s);
  bool low = r<0, high = r> int(2u * s);
  int r_low = r + int(2u * s - 1u), r_high = r - int(2u * s + 1u);
  r = pickI(low, r_low, pickI(high, r_high, r));
  s = pickU(low, s - 1u, pickU(high, s + 1u, s));
  // sqrt(N) is never exactly half-way; it is above s + 1/2 when N > s^2 + s
  bool beyond = r > int(s);
  float result = packRounded(0u, half_exp + 127, s, pickI(beyond, 1, -1), r != 0);
  return pickF(SIM_CORRECT_MATH, pickF(special, uintBitsToFloat(answer), result), deviceSqrt(x));
}

#ifdef __cplusplus
// The CPU's sqrtss and divss are correctly rounded: the same bits as exactSqrt and exactDiv.
SIM_INLINE float simSqrt(float x) { return std::sqrt(x); }
SIM_INLINE float simDiv(float a, float b) { return a / b; }
#else
float simSqrt(float x) { return exactSqrt(x); }
float simDiv(float a, float b) { return exactDiv(a, b); }
#endif

#define SIM_PI 3.14159265f

/// atan2(y, x) in (-pi, pi] from adds, multiplies and one simDiv, so every device gives the same
/// bits (a device's atan is not correctly rounded): the ratio t of the smaller to the larger
/// magnitude (past tan(pi / 8), (small - big) / (small + big) and pi / 4 more), then Cephes' atanf
/// polynomial (about 1e-7 rad from the true angle), unfolded into the octant. atan2(0, 0) is 0.
SIM_INLINE float simAtan2(float y, float x) {
  float ax = abs(x), ay = abs(y);
  float big = max(ax, ay), small = min(ax, ay);
  if (!(big > 0.0f)) return 0.0f;
  bool turn = small > 0.41421356f * big;
  float t = simDiv(turn ? small - big : small, turn ? small + big : big);
  float base = turn ? 0.78539816f : 0.0f;
  float z = t * t;
  float a =
      base + ((((0.0805374449538f * z - 0.138776856032f) * z + 0.199777106478f) * z - 0.333329491539f) * z * t + t);
  if (ay > ax) a = 1.57079633f - a;
  if (x < 0.0f) a = SIM_PI - a;
  return y < 0.0f ? -a : a;
}

/// The angle a in (-pi, pi]: a - 2 pi or a + 2 pi for a in (-3 pi, 3 pi).
SIM_INLINE float wrapAngle(float a) {
  if (a > SIM_PI) return a - 2.0f * SIM_PI;
  if (a <= -SIM_PI) return a + 2.0f * SIM_PI;
  return a;
}

#endif
