// SSE kernels of the CPU solver (SSE2 is part of x86-64, so this file needs no extra flags); the
// 8-wide projection is in kernels_avx.cpp, built with -mavx.
#include "simd_kernels.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "cpu_collision.h"
#if defined(TENDER_CPU_AVX)
#include "kernels_avx.h"
#endif
#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace tender::simd {

using namespace shaderio;

bool hasAvx() {
#if defined(TENDER_CPU_AVX)
  static const bool available = avx::available();
  return available;
#else
  return false;
#endif
}

uint32_t project8([[maybe_unused]] float* pos, [[maybe_unused]] const uint32_t* a, [[maybe_unused]] const uint32_t* b,
                  [[maybe_unused]] const float* rest, [[maybe_unused]] const uint32_t* kind,
                  [[maybe_unused]] const float stiffness[4], uint32_t begin, [[maybe_unused]] uint32_t end) {
#if defined(TENDER_CPU_AVX)
  if (hasAvx()) return avx::projectColor(pos, a, b, rest, kind, stiffness, begin, end);
#endif
  return begin;
}

uint32_t shorten([[maybe_unused]] float* pos, [[maybe_unused]] const uint32_t* a, [[maybe_unused]] const uint32_t* b,
                 [[maybe_unused]] const float* rest, [[maybe_unused]] const uint32_t* kind,
                 [[maybe_unused]] float reach, [[maybe_unused]] float tear_factor, [[maybe_unused]] bool tears,
                 uint32_t begin, [[maybe_unused]] uint32_t end) {
#if defined(TENDER_CPU_AVX)
  if (hasAvx()) return avx::shortenColor(pos, a, b, rest, kind, {reach, tear_factor, tears}, begin, end);
#endif
  return begin;
}

uint32_t projectHinges([[maybe_unused]] float* pos, [[maybe_unused]] float* state,
                       [[maybe_unused]] const uint32_t* corners, [[maybe_unused]] const uint32_t* hinge,
                       [[maybe_unused]] uint32_t first_diagonal, [[maybe_unused]] float alpha, uint32_t begin,
                       [[maybe_unused]] uint32_t end) {
#if defined(TENDER_CPU_AVX)
  if (hasAvx()) return avx::projectHinges(pos, state, {corners, hinge, first_diagonal, alpha}, begin, end);
#endif
  return begin;
}

uint32_t creaseHinges([[maybe_unused]] float* pos, [[maybe_unused]] float* state,
                      [[maybe_unused]] const uint32_t* corners, [[maybe_unused]] const uint32_t* torn,
                      [[maybe_unused]] float yield0, [[maybe_unused]] float hardening, uint32_t begin,
                      [[maybe_unused]] uint32_t end) {
#if defined(TENDER_CPU_AVX)
  if (hasAvx()) return avx::creaseHinges(pos, state, corners, torn, yield0, hardening, begin, end);
#endif
  return begin;
}

uint32_t project(float* pos, const uint32_t* a, const uint32_t* b, const float* rest, const uint32_t* kind,
                 const float stiffness[4], uint32_t begin, uint32_t end) {
  const uint32_t k = project8(pos, a, b, rest, kind, stiffness, begin, end);
  return project4(pos, a, b, rest, kind, stiffness, k, end);
}

#if defined(__SSE2__)

namespace {

// For each 4-bit hit mask: the indices of its set lanes packed to the front, then the hit count.
alignas(16) constexpr auto kPackedLanes = [] {
  std::array<std::array<uint32_t, 8>, 16> t{};
  for (uint32_t mask = 0; mask < 16; ++mask)
    for (uint32_t lane = 0; lane < 4; ++lane)
      if ((mask >> lane) & 1u) t[mask][t[mask][4]++] = lane;
  return t;
}();

// Bucket masks of the 27 neighbour cells (bit dz*9 + dy*3 + dx, offsets +1) selected by the
// needed -1/0/+1 sides (bits 0, 1, 2) of the x, y and z axis.
constexpr auto kAxisMasks = [] {
  std::array<std::array<uint32_t, 8>, 3> m{};
  for (uint32_t sides = 0; sides < 8; ++sides)
    for (uint32_t b = 0; b < 27; ++b) {
      if ((sides >> (b % 3)) & 1u) m[0][sides] |= 1u << b;
      if ((sides >> (b / 3 % 3)) & 1u) m[1][sides] |= 1u << b;
      if ((sides >> (b / 9)) & 1u) m[2][sides] |= 1u << b;
    }
  return m;
}();

// The sorted adjacency list of one particle, for the membership tests of its collision hits.
// Lists of up to 16 entries sit in four registers (the unused lanes hold ~0u, never a particle),
// so a test is a few compares with no branch on the data.
class Adjacency {
public:
  Adjacency(const uint32_t* adj, uint32_t count) : adj_(adj), count_(count) {
    if (count <= 16) {
      const __m128i last = _mm_set1_epi32(int(count) - 1);
      for (int g = 0; g < 4; ++g) {
        const __m128i lane = _mm_setr_epi32(4 * g, 4 * g + 1, 4 * g + 2, 4 * g + 3);
        const __m128i entries = _mm_loadu_si128(reinterpret_cast<const __m128i*>(adj + 4 * g));
        q_[g] = _mm_or_si128(entries, _mm_cmpgt_epi32(lane, last));
      }
    }
  }

  bool contains(uint32_t j) const {
    if (count_ > 16) return std::binary_search(adj_, adj_ + count_, j);
    const __m128i key = _mm_set1_epi32(int(j));
    const __m128i eq = _mm_or_si128(_mm_or_si128(_mm_cmpeq_epi32(q_[0], key), _mm_cmpeq_epi32(q_[1], key)),
                                    _mm_or_si128(_mm_cmpeq_epi32(q_[2], key), _mm_cmpeq_epi32(q_[3], key)));
    return _mm_movemask_epi8(eq) != 0;
  }

private:
  const uint32_t* adj_;
  uint32_t count_;
  __m128i q_[4];
};

// |b - a| of four constraints at once: len = sqrt(dot(d, d)) with d = b - a and
// dot = (x*x + y*y) + z*z, as solveDistance and shouldTear form it. Rows pa/pb are the four
// particles; on return they are transposed to x, y, z, w.
inline __m128 lengths(__m128& ax, __m128& ay, __m128& az, __m128& aw, __m128& bx, __m128& by, __m128& bz, __m128& bw,
                      __m128& dx, __m128& dy, __m128& dz) {
  _MM_TRANSPOSE4_PS(ax, ay, az, aw);
  _MM_TRANSPOSE4_PS(bx, by, bz, bw);
  dx = _mm_sub_ps(bx, ax);
  dy = _mm_sub_ps(by, ay);
  dz = _mm_sub_ps(bz, az);
  return _mm_sqrt_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz)));
}

} // namespace

uint32_t project4(float* pos, const uint32_t* ca, const uint32_t* cb, const float* rest, const uint32_t* kind,
                  const float stiffness[4], uint32_t begin, uint32_t end) {
  const __m128 zero = _mm_setzero_ps(), tiny = _mm_set1_ps(1e-9f), sign = _mm_set1_ps(-0.0f);
  uint32_t k = begin;
  for (; k + 4 <= end; k += 4) {
    float *a0 = pos + 4 * size_t(ca[k]), *a1 = pos + 4 * size_t(ca[k + 1]);
    float *a2 = pos + 4 * size_t(ca[k + 2]), *a3 = pos + 4 * size_t(ca[k + 3]);
    float *b0 = pos + 4 * size_t(cb[k]), *b1 = pos + 4 * size_t(cb[k + 1]);
    float *b2 = pos + 4 * size_t(cb[k + 2]), *b3 = pos + 4 * size_t(cb[k + 3]);
    const __m128 pa0 = _mm_loadu_ps(a0), pa1 = _mm_loadu_ps(a1), pa2 = _mm_loadu_ps(a2), pa3 = _mm_loadu_ps(a3);
    const __m128 pb0 = _mm_loadu_ps(b0), pb1 = _mm_loadu_ps(b1), pb2 = _mm_loadu_ps(b2), pb3 = _mm_loadu_ps(b3);
    // One register per component, and the lengths
    __m128 ax = pa0, ay = pa1, az = pa2, aw = pa3, bx = pb0, by = pb1, bz = pb2, bw = pb3, dx, dy, dz;
    const __m128 len = lengths(ax, ay, az, aw, bx, by, bz, bw, dx, dy, dz);
    const __m128 wsum = _mm_add_ps(aw, bw);
    const __m128 r = _mm_loadu_ps(rest + k);
    const __m128 stiff =
        _mm_setr_ps(stiffness[kind[k]], stiffness[kind[k + 1]], stiffness[kind[k + 2]], stiffness[kind[k + 3]]);
    // s = stiffness * (len - rest) / (len * wsum); corrections are zero unless wsum > 0 and len > 1e-9
    const __m128 s = _mm_div_ps(_mm_mul_ps(stiff, _mm_sub_ps(len, r)), _mm_mul_ps(len, wsum));
    const __m128 ok = _mm_and_ps(_mm_cmpgt_ps(wsum, zero), _mm_cmpgt_ps(len, tiny));
    const __m128 ta = _mm_mul_ps(s, aw), tb = _mm_mul_ps(_mm_xor_ps(s, sign), bw);
    __m128 dax = _mm_and_ps(_mm_mul_ps(dx, ta), ok), day = _mm_and_ps(_mm_mul_ps(dy, ta), ok);
    __m128 daz = _mm_and_ps(_mm_mul_ps(dz, ta), ok), daw = zero;
    __m128 dbx = _mm_and_ps(_mm_mul_ps(dx, tb), ok), dby = _mm_and_ps(_mm_mul_ps(dy, tb), ok);
    __m128 dbz = _mm_and_ps(_mm_mul_ps(dz, tb), ok), dbw = zero;
    // Back to one register per particle (w correction 0), then p += correction
    _MM_TRANSPOSE4_PS(dax, day, daz, daw);
    _MM_TRANSPOSE4_PS(dbx, dby, dbz, dbw);
    _mm_storeu_ps(a0, _mm_add_ps(pa0, dax));
    _mm_storeu_ps(a1, _mm_add_ps(pa1, day));
    _mm_storeu_ps(a2, _mm_add_ps(pa2, daz));
    _mm_storeu_ps(a3, _mm_add_ps(pa3, daw));
    _mm_storeu_ps(b0, _mm_add_ps(pb0, dbx));
    _mm_storeu_ps(b1, _mm_add_ps(pb1, dby));
    _mm_storeu_ps(b2, _mm_add_ps(pb2, dbz));
    _mm_storeu_ps(b3, _mm_add_ps(pb3, dbw));
  }
  return k;
}

uint64_t stretched(const float* pos, const uint32_t* ca, const uint32_t* cb, const float* rest, float tear_factor,
                   uint32_t k, uint32_t n) {
  const __m128 factor = _mm_set1_ps(tear_factor);
  uint64_t over = 0;
  for (uint32_t l = 0; l + 4 <= n; l += 4) {
    const uint32_t c = k + l;
    __m128 ax = _mm_loadu_ps(pos + 4 * size_t(ca[c])), ay = _mm_loadu_ps(pos + 4 * size_t(ca[c + 1]));
    __m128 az = _mm_loadu_ps(pos + 4 * size_t(ca[c + 2])), aw = _mm_loadu_ps(pos + 4 * size_t(ca[c + 3]));
    __m128 bx = _mm_loadu_ps(pos + 4 * size_t(cb[c])), by = _mm_loadu_ps(pos + 4 * size_t(cb[c + 1]));
    __m128 bz = _mm_loadu_ps(pos + 4 * size_t(cb[c + 2])), bw = _mm_loadu_ps(pos + 4 * size_t(cb[c + 3]));
    __m128 dx, dy, dz;
    // sqrt(dot(d, d)) > rest * tear_factor
    const __m128 len = lengths(ax, ay, az, aw, bx, by, bz, bw, dx, dy, dz);
    const __m128 limit = _mm_mul_ps(_mm_loadu_ps(rest + c), factor);
    over |= uint64_t(_mm_movemask_ps(_mm_cmpgt_ps(len, limit))) << l;
  }
  return over;
}

/// The buckets of the 27 cells around a particle's cell (dz, dy, dx order), looked up when first
/// needed and reused while the cell repeats (the particles come in bucket order).
struct NeighbourBuckets {
  uint32_t first[27], last[27];
  ivec4 cell[27];
  ivec3 cached_cell{0};
  bool cached = false;
  uint32_t known = 0;    // bit b: bucket b is looked up for the current cell
  uint32_t nonempty = 0; // bit b: bucket b holds particles (among the known)

  /// The non-empty buckets a particle at `pi` in cell `ci` visits: on a side within `reach` (in
  /// cell units) on every axis, all three sides of an axis when unsure.
  [[gnu::always_inline]] uint32_t visit(vec3 pi, ivec3 ci, const SimUniforms& u, float reach, const uint32_t* start) {
    if (!cached || ci != cached_cell) {
      cached_cell = ci;
      cached = true;
      known = nonempty = 0;
    }
    uint32_t visit = (1u << 27) - 1u;
    const vec3 scaled = pi * u.inv_cell;
    for (int a = 0; a < 3; ++a) {
      const float f = scaled[a] - float(ci[a]);
      const bool sure = std::fabs(scaled[a]) < 1024.0f && f >= 0.0f && f <= 1.0f; // rounding well inside the margin
      const uint32_t sides = 2u | (!sure || !(f >= reach) ? 1u : 0u) | (!sure || !(1.0f - f >= reach) ? 4u : 0u);
      visit &= kAxisMasks[a][sides];
    }
    for (uint32_t missing = visit & ~known; missing; missing &= missing - 1u) {
      const int b = __builtin_ctz(missing);
      const ivec3 c = ci + ivec3(b % 3 - 1, b / 3 % 3 - 1, b / 9 - 1);
      const uint32_t h = hashCell(c, u.hash_mask);
      first[b] = start[h];
      last[b] = start[h + 1];
      cell[b] = ivec4(c, 0);
      nonempty |= start[h] < start[h + 1] ? 1u << b : 0u;
    }
    known |= visit;
    return visit & nonempty;
  }
};

bool gather(const GatherArrays& g, const SimUniforms& u, uint32_t begin, uint32_t end, float search, bool build) {
  const float r = u.collision_radius, r2 = r * r, search2 = search * search;
  bool fits = true;
  const float *sx = g.x, *sy = g.y, *sz = g.z;
  const uint32_t* slots = g.particle;
  const ivec4* coords = g.cell;
  const uint32_t* start = g.cell_start;

  NeighbourBuckets buckets;
  // A neighbour cell on one side can hold a particle within `search` only when the particle is
  // closer than that to that side of its own cell (`search` never exceeds a cell). The test is
  // in cell units with a generous margin, so no contributing cell is ever skipped.
  const float reach = search * u.inv_cell + 1e-3f;
  // Slots within `search`, in summation order, with their bucket; filled without branches.
  constexpr uint32_t kHitCapacity = 64;
  uint32_t hit_slot[kHitCapacity + 4];
  uint8_t hit_bucket[kHitCapacity + 4];

  for (uint32_t k = begin; k < end; ++k) {
    const uint32_t i = slots[k];
    const vec3 pi(sx[k], sy[k], sz[k]);
    const ivec3 ci(coords[k]);
    uint32_t visit = buckets.visit(pi, ci, u, reach, start);
    const Adjacency adjacency(g.adj_list + g.adj_offsets[i], g.adj_offsets[i + 1] - g.adj_offsets[i]);
    vec3 sum(0.0f);
    uint32_t hit_count = 0;
    uint32_t* candidates = build ? g.candidates + size_t(SIM_CANDIDATE_STRIDE) * i : nullptr;
    uint32_t found = 0;
    // Sums the hits so far (and lists the candidates). Skips the particle itself (slot k), particles of
    // other cells sharing a bucket (each is counted from its own cell) and connected particles.
    auto flush = [&] {
      for (uint32_t t = 0; t < hit_count; ++t) {
        const uint32_t m = hit_slot[t];
        if (m == k || coords[m] != buckets.cell[hit_bucket[t]] || adjacency.contains(slots[m])) continue;
        const vec3 pj(sx[m], sy[m], sz[m]);
        if (candidates) found = addCandidate(candidates, found, slots[m]);
        const vec3 d = pi - pj;
        if (dot3(d, d) < r2) sum += repulsion(pi, pj, r, u.collision_stiffness);
      }
      hit_count = 0;
    };
    const __m128 px = _mm_set1_ps(pi.x), py = _mm_set1_ps(pi.y), pz = _mm_set1_ps(pi.z), vr2 = _mm_set1_ps(search2);
    while (visit) { // ascending bucket index: dz, dy, dx order
      const uint32_t b = uint32_t(__builtin_ctz(visit));
      visit &= visit - 1u;
      const uint32_t first = buckets.first[b], last = buckets.last[b];
      for (uint32_t m = first; m < last; m += 4) {
        // d = pi - pj; the same dot3(d, d) < search2 test as the scalar maths, four at a time
        const __m128 dx = _mm_sub_ps(px, _mm_loadu_ps(sx + m));
        const __m128 dy = _mm_sub_ps(py, _mm_loadu_ps(sy + m));
        const __m128 dz = _mm_sub_ps(pz, _mm_loadu_ps(sz + m));
        const __m128 d2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
        uint32_t hits = uint32_t(_mm_movemask_ps(_mm_cmplt_ps(d2, vr2)));
        if (last - m < 4) hits &= (1u << (last - m)) - 1u;
        // Append the hit lanes, packed to the front: four slots and buckets stored, the hits kept
        const __m128i lanes = _mm_load_si128(reinterpret_cast<const __m128i*>(kPackedLanes[hits].data()));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(hit_slot + hit_count),
                         _mm_add_epi32(_mm_set1_epi32(int(m)), lanes));
        const uint32_t bucket4 = b * 0x01010101u;
        std::memcpy(hit_bucket + hit_count, &bucket4, 4);
        hit_count += kPackedLanes[hits][4];
        if (hit_count > kHitCapacity) flush();
      }
    }
    flush();
    fits = endGather(g, k, i, pi, sum, candidates, found) && fits;
  }
  return fits;
}

#else // no SSE: kBuilt is false and the solver never calls these; they fall back to the reference

uint32_t project4(float*, const uint32_t*, const uint32_t*, const float*, const uint32_t*, const float[4],
                  uint32_t begin, uint32_t) {
  return begin;
}

uint64_t stretched(const float*, const uint32_t*, const uint32_t*, const float*, float, uint32_t, uint32_t n) {
  return n >= 64 ? ~uint64_t(0) : (uint64_t(1) << n) - 1u; // every lane goes through shouldTear
}

bool gather(const GatherArrays& g, const SimUniforms& u, uint32_t begin, uint32_t end, float search, bool build) {
  return gatherReference(g, u, begin, end, search, build);
}

#endif

} // namespace tender::simd
