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

/// The device's square root of x >= 0, made inexact when SIM_INEXACT_MATH.
SIM_INLINE float deviceSqrt(float x) {
  float r = sqrt(x);
  if (SIM_INEXACT_MATH && r > 0.0f && r < 3.0e38f)
    r = uintBitsToFloat(floatBitsToUint(r) + inexactOffset(floatBitsToUint(x)));
  return r;
}

/// The device's quotient a / b, made inexact when SIM_INEXACT_MATH.
SIM_INLINE float deviceDiv(float a, float b) {
  float q = a / b;
  float m = abs(q);
  if (SIM_INEXACT_MATH && m > 1.0e-37f && m < 3.0e38f)
    q = uintBitsToFloat(floatBitsToUint(q) + inexactOffset(floatBitsToUint(a) * 0x9E3779B9u ^ floatBitsToUint(b)));
  return q;
}

/// Significand (x: in [2^23, 2^24)) and unbiased exponent (y) of the finite non-zero float with
/// magnitude bits `bits`; a denormal is normalised.
SIM_INLINE ivec2 splitFloat(uint bits) {
  uint field = bits >> 23u;
  if (field != 0u) return ivec2(int((bits & 0x7FFFFFu) | 0x800000u), int(field) - 127);
  int shift = 23 - findMSB(bits);
  return ivec2(int(bits << uint(shift)), -126 - shift);
}

/// The float with sign `sign`, biased exponent `biased` (<= 0: denormal) and significand q in
/// [2^23, 2^24) rounded to nearest even by `above`: the rest beyond q compared with half an ulp (-1
/// below, 0 exactly half, 1 above; `inexact`: anything at all beyond q).
SIM_INLINE float packRounded(uint sign, int biased, uint q, int above, bool inexact) {
  if (biased >= 255) return uintBitsToFloat(sign | 0x7F800000u);
  if (SIM_FLUSH_DENORMALS && biased <= 0) {
    // Flushed unless it rounds up to the smallest normal (tininess after rounding, as x86 FTZ)
    uint up = above > 0 || (above == 0 && (q & 1u) != 0u) ? 1u : 0u;
    return uintBitsToFloat(sign | (biased == 0 && q + up == 0x1000000u ? 0x800000u : 0u));
  }
  if (biased >= 1) {
    uint up = above > 0 || (above == 0 && (q & 1u) != 0u) ? 1u : 0u;
    // A carry out of the significand moves into the exponent (up to infinity)
    return uintBitsToFloat(sign | ((uint(biased - 1) << 23u) + q + up));
  }
  uint s = uint(1 - biased); // denormal: q >> s, rounded on the bits shifted out
  if (s > 25u) return uintBitsToFloat(sign);
  uint m = q >> s;
  uint guard = (q >> (s - 1u)) & 1u;
  bool sticky = (q & ((1u << (s - 1u)) - 1u)) != 0u || inexact;
  uint up = guard != 0u && (sticky || (m & 1u) != 0u) ? 1u : 0u;
  return uintBitsToFloat(sign | (m + up));
}

/// Correctly rounded a / b (round to nearest even, denormals kept) on any device.
SIM_INLINE float exactDiv(float a, float b) {
  if (!SIM_CORRECT_MATH) return deviceDiv(a, b);
  uint ua = floatBitsToUint(a), ub = floatBitsToUint(b);
  if (SIM_FLUSH_DENORMALS) { // denormal inputs read as zero
    if ((ua & 0x7F800000u) == 0u) ua &= 0x80000000u;
    if ((ub & 0x7F800000u) == 0u) ub &= 0x80000000u;
  }
  uint sign = (ua ^ ub) & 0x80000000u;
  uint xa = ua & 0x7FFFFFFFu, xb = ub & 0x7FFFFFFFu;
  const uint kInf = 0x7F800000u, kNaN = 0x7FC00000u;
  if (xa > kInf || xb > kInf || (xa == kInf && xb == kInf) || (xa == 0u && xb == 0u)) return uintBitsToFloat(kNaN);
  if (xa == kInf || xb == 0u) return uintBitsToFloat(sign | kInf);
  if (xa == 0u || xb == kInf) return uintBitsToFloat(sign);
  ivec2 fa = splitFloat(xa), fb = splitFloat(xb);
  uint ma = uint(fa.x), mb = uint(fb.x);
  // q = floor(ma 2^shift / mb) in [2^23, 2^24); the result is q 2^(e - 23)
  bool ge = ma >= mb;
  uint shift = ge ? 23u : 24u;
  int e = fa.y - fb.y - (ge ? 0 : 1);
  // Start from the device's quotient of the significands (both in [1, 2), so it is within a few
  // ULP), then step to the floor: the remainder ma 2^shift - q mb is exact modulo 2^32 and small.
  float approx =
      deviceDiv(uintBitsToFloat(0x3F800000u | (ma & 0x7FFFFFu)), uintBitsToFloat(0x3F800000u | (mb & 0x7FFFFFu)));
  uint q = clamp(uint(approx * (ge ? 8388608.0f : 16777216.0f)), 0x800000u, 0xFFFFFFu);
  int r = int((ma << shift) - q * mb);
  // q is off by a few units: an estimate of floor(r / mb) (within one of it: |r / mb| <= 5, and
  // 1.5 - x / 2 is within 12 % of 1 / x on [1, 2), so no second division) and one last step
  float inv_mb = (1.5f - 0.5f * uintBitsToFloat(0x3F800000u | (mb & 0x7FFFFFu))) * 1.1920929e-7f;
  int d = int(floor(float(r) * inv_mb));
  q += uint(d);
  r -= d * int(mb);
  if (r < 0) {
    q -= 1u;
    r += int(mb);
  } else if (r >= int(mb)) {
    q += 1u;
    r -= int(mb);
  }
  uint twice = 2u * uint(r);
  int above = twice > mb ? 1 : twice == mb ? 0 : -1;
  return packRounded(sign, e + 127, q, above, r != 0);
}

/// Correctly rounded sqrt(x) (round to nearest even, denormals kept) on any device.
SIM_INLINE float exactSqrt(float x) {
  if (!SIM_CORRECT_MATH) return deviceSqrt(x);
  uint ux = floatBitsToUint(x);
  if (SIM_FLUSH_DENORMALS && (ux & 0x7F800000u) == 0u) ux &= 0x80000000u; // a denormal reads as zero
  if ((ux & 0x7FFFFFFFu) == 0u || ux == 0x7F800000u) return uintBitsToFloat(ux);
  if (ux > 0x7F800000u) return uintBitsToFloat(0x7FC00000u); // NaN or negative
  ivec2 f = splitFloat(ux);
  uint m = uint(f.x);
  // x = m 2^(e - 23); with an even exponent left over, sqrt(x) = sqrt(N) 2^(half - 23) where
  // N = m 2^(23 or 24) lies in [2^46, 2^48) and s = floor(sqrt(N)) in [2^23, 2^24)
  bool odd = (f.y & 1) != 0;
  int half_exp = (f.y - (odd ? 1 : 0)) / 2;
  float scaled = uintBitsToFloat(0x3F800000u | (m & 0x7FFFFFu)) * (odd ? 2.0f : 1.0f); // N / 2^46
  uint s = clamp(uint(deviceSqrt(scaled) * 8388608.0f), 0x800000u, 0xFFFFFFu);
  // r = N - s^2, exact modulo 2^32 and small; s is the floor when 0 <= r <= 2s
  uint n = m << (odd ? 24u : 23u);
  int r = int(n - s * s);
  // s is off by a few units: an estimate of the step r / 2s (within one of it: |r / 2s| <= 5, and
  // 1.5 - x / 2 is within 12 % of 1 / x on [1, 2), so no division), then one last step
  float inv_2s = (1.5f - 0.5f * float(s) * 1.1920929e-7f) * 5.9604645e-8f;
  s += uint(int(floor(float(r) * inv_2s)));
  r = int(n - s * s);
  if (r < 0) {
    s -= 1u;
    r += int(2u * s + 1u);
  } else if (r > int(2u * s)) {
    r -= int(2u * s + 1u);
    s += 1u;
  }
  // sqrt(N) is never exactly half-way; it is above s + 1/2 when N > s^2 + s
  return packRounded(0u, half_exp + 127, s, r > int(s) ? 1 : -1, r != 0);
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
