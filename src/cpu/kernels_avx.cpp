// Built with -mavx (and no FMA): the same IEEE operations as the scalar reference, 8 lanes wide.
#include "kernels_avx.h"

#include <immintrin.h>

namespace tender::avx {
namespace {

// Two vec4 rows as one register: lo = p0, hi = p1.
inline __m256 loadRows(const float* p0, const float* p1) {
  return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(p0)), _mm_loadu_ps(p1), 1);
}

// Transposes four registers of two rows each into components (x, y, z, w) within each half.
inline void transpose(__m256& r0, __m256& r1, __m256& r2, __m256& r3) {
  const __m256 t0 = _mm256_unpacklo_ps(r0, r1), t1 = _mm256_unpacklo_ps(r2, r3);
  const __m256 t2 = _mm256_unpackhi_ps(r0, r1), t3 = _mm256_unpackhi_ps(r2, r3);
  r0 = _mm256_shuffle_ps(t0, t1, _MM_SHUFFLE(1, 0, 1, 0));
  r1 = _mm256_shuffle_ps(t0, t1, _MM_SHUFFLE(3, 2, 3, 2));
  r2 = _mm256_shuffle_ps(t2, t3, _MM_SHUFFLE(1, 0, 1, 0));
  r3 = _mm256_shuffle_ps(t2, t3, _MM_SHUFFLE(3, 2, 3, 2));
}

inline void storeRows(float* p0, float* p1, __m256 v) {
  _mm_storeu_ps(p0, _mm256_castps256_ps128(v));
  _mm_storeu_ps(p1, _mm256_extractf128_ps(v, 1));
}

} // namespace

bool available() {
#if defined(__GNUC__)
  return __builtin_cpu_supports("avx");
#else
  return false;
#endif
}

uint32_t projectColor(float* pos, const uint32_t* a, const uint32_t* b, const float* rest, const uint32_t* kind,
                      const float stiffness[4], uint32_t begin, uint32_t end) {
  const __m256 zero = _mm256_setzero_ps(), tiny = _mm256_set1_ps(1e-9f), sign = _mm256_set1_ps(-0.0f);
  const __m256 table = _mm256_setr_ps(stiffness[0], stiffness[1], stiffness[2], stiffness[3], stiffness[0],
                                      stiffness[1], stiffness[2], stiffness[3]);
  uint32_t k = begin;
  for (; k + 8 <= end; k += 8) {
    // Lane l of the low half is constraint k + l, of the high half k + 4 + l.
    float* pa[8];
    float* pb[8];
    for (uint32_t l = 0; l < 8; ++l) {
      pa[l] = pos + 4 * size_t(a[k + l]);
      pb[l] = pos + 4 * size_t(b[k + l]);
    }
    const __m256 ra0 = loadRows(pa[0], pa[4]), ra1 = loadRows(pa[1], pa[5]);
    const __m256 ra2 = loadRows(pa[2], pa[6]), ra3 = loadRows(pa[3], pa[7]);
    const __m256 rb0 = loadRows(pb[0], pb[4]), rb1 = loadRows(pb[1], pb[5]);
    const __m256 rb2 = loadRows(pb[2], pb[6]), rb3 = loadRows(pb[3], pb[7]);
    __m256 ax = ra0, ay = ra1, az = ra2, aw = ra3;
    transpose(ax, ay, az, aw);
    __m256 bx = rb0, by = rb1, bz = rb2, bw = rb3;
    transpose(bx, by, bz, bw);
    // d = b - a; len = sqrt(dot(d, d)) with dot = (x*x + y*y) + z*z
    const __m256 dx = _mm256_sub_ps(bx, ax), dy = _mm256_sub_ps(by, ay), dz = _mm256_sub_ps(bz, az);
    const __m256 len = _mm256_sqrt_ps(
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)), _mm256_mul_ps(dz, dz)));
    const __m256 wsum = _mm256_add_ps(aw, bw);
    const __m256 r = _mm256_loadu_ps(rest + k);
    const __m256 st = _mm256_permutevar_ps(table, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(kind + k)));
    // s = stiffness * (len - rest) / (len * wsum); corrections are zero unless wsum > 0 and len > 1e-9
    const __m256 s = _mm256_div_ps(_mm256_mul_ps(st, _mm256_sub_ps(len, r)), _mm256_mul_ps(len, wsum));
    const __m256 ok = _mm256_and_ps(_mm256_cmp_ps(wsum, zero, _CMP_GT_OQ), _mm256_cmp_ps(len, tiny, _CMP_GT_OQ));
    const __m256 ta = _mm256_mul_ps(s, aw), tb = _mm256_mul_ps(_mm256_xor_ps(s, sign), bw);
    __m256 dax = _mm256_and_ps(_mm256_mul_ps(dx, ta), ok), day = _mm256_and_ps(_mm256_mul_ps(dy, ta), ok);
    __m256 daz = _mm256_and_ps(_mm256_mul_ps(dz, ta), ok), daw = zero;
    __m256 dbx = _mm256_and_ps(_mm256_mul_ps(dx, tb), ok), dby = _mm256_and_ps(_mm256_mul_ps(dy, tb), ok);
    __m256 dbz = _mm256_and_ps(_mm256_mul_ps(dz, tb), ok), dbw = zero;
    // Back to rows (w correction 0), then p += correction.
    transpose(dax, day, daz, daw);
    transpose(dbx, dby, dbz, dbw);
    storeRows(pa[0], pa[4], _mm256_add_ps(ra0, dax));
    storeRows(pa[1], pa[5], _mm256_add_ps(ra1, day));
    storeRows(pa[2], pa[6], _mm256_add_ps(ra2, daz));
    storeRows(pa[3], pa[7], _mm256_add_ps(ra3, daw));
    storeRows(pb[0], pb[4], _mm256_add_ps(rb0, dbx));
    storeRows(pb[1], pb[5], _mm256_add_ps(rb1, dby));
    storeRows(pb[2], pb[6], _mm256_add_ps(rb2, dbz));
    storeRows(pb[3], pb[7], _mm256_add_ps(rb3, dbw));
  }
  return k;
}

} // namespace tender::avx
