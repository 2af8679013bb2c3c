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

// The ends of eight constraints k to k + 7 of a colour (no two share a particle): lane l of the low
// half is constraint k + l, of the high half k + 4 + l. Holds the rows as loaded and, transposed,
// their components.
struct Ends {
  float* pa[8];
  float* pb[8];
  __m256 ra[4], rb[4];
  __m256 ax, ay, az, aw, bx, by, bz, bw;
};

inline Ends loadEnds(float* pos, const uint32_t* a, const uint32_t* b, uint32_t k) {
  Ends e;
  for (uint32_t l = 0; l < 8; ++l) {
    e.pa[l] = pos + 4 * size_t(a[k + l]);
    e.pb[l] = pos + 4 * size_t(b[k + l]);
  }
  for (uint32_t r = 0; r < 4; ++r) {
    e.ra[r] = loadRows(e.pa[r], e.pa[r + 4]);
    e.rb[r] = loadRows(e.pb[r], e.pb[r + 4]);
  }
  e.ax = e.ra[0], e.ay = e.ra[1], e.az = e.ra[2], e.aw = e.ra[3];
  transpose(e.ax, e.ay, e.az, e.aw);
  e.bx = e.rb[0], e.by = e.rb[1], e.bz = e.rb[2], e.bw = e.rb[3];
  transpose(e.bx, e.by, e.bz, e.bw);
  return e;
}

// Adds the corrections (components, w 0) to the ends: back to rows, then p += correction.
inline void storeEnds(const Ends& e, __m256 dax, __m256 day, __m256 daz, __m256 dbx, __m256 dby, __m256 dbz) {
  __m256 daw = _mm256_setzero_ps(), dbw = _mm256_setzero_ps();
  transpose(dax, day, daz, daw);
  transpose(dbx, dby, dbz, dbw);
  const __m256 da[4] = {dax, day, daz, daw}, db[4] = {dbx, dby, dbz, dbw};
  for (uint32_t r = 0; r < 4; ++r) {
    storeRows(e.pa[r], e.pa[r + 4], _mm256_add_ps(e.ra[r], da[r]));
    storeRows(e.pb[r], e.pb[r + 4], _mm256_add_ps(e.rb[r], db[r]));
  }
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
    const Ends e = loadEnds(pos, a, b, k);
    const __m256 &ax = e.ax, &ay = e.ay, &az = e.az, &aw = e.aw, &bx = e.bx, &by = e.by, &bz = e.bz, &bw = e.bw;
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
    storeEnds(e, _mm256_and_ps(_mm256_mul_ps(dx, ta), ok), _mm256_and_ps(_mm256_mul_ps(dy, ta), ok),
              _mm256_and_ps(_mm256_mul_ps(dz, ta), ok), _mm256_and_ps(_mm256_mul_ps(dx, tb), ok),
              _mm256_and_ps(_mm256_mul_ps(dy, tb), ok), _mm256_and_ps(_mm256_mul_ps(dz, tb), ok));
  }
  return k;
}

uint32_t shortenColor(float* pos, const uint32_t* a, const uint32_t* b, const float* rest, const uint32_t* kind,
                      const ShortenLimit& limit, uint32_t begin, uint32_t end) {
  const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f), sign = _mm256_set1_ps(-0.0f);
  const __m256 reach = _mm256_set1_ps(limit.reach), reach2 = _mm256_set1_ps(limit.reach * limit.reach);
  const __m256 tear_factor = _mm256_set1_ps(limit.tear_factor);
  uint32_t k = begin;
  for (; k + 8 <= end; k += 8) {
    const Ends e = loadEnds(pos, a, b, k);
    const __m256 &ax = e.ax, &ay = e.ay, &az = e.az, &aw = e.aw, &bx = e.bx, &by = e.by, &bz = e.bz, &bw = e.bw;
    // shortenEdge: w 1 or 0 by pos.w > 0; d = b - a, len2 = (x*x + y*y) + z*z, len = sqrt(len2)
    const __m256 wa = _mm256_and_ps(_mm256_cmp_ps(aw, zero, _CMP_GT_OQ), one);
    const __m256 wb = _mm256_and_ps(_mm256_cmp_ps(bw, zero, _CMP_GT_OQ), one);
    const __m256 wsum = _mm256_add_ps(wa, wb);
    const __m256 dx = _mm256_sub_ps(bx, ax), dy = _mm256_sub_ps(by, ay), dz = _mm256_sub_ps(bz, az);
    const __m256 len2 =
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)), _mm256_mul_ps(dz, dz));
    const __m256 len = _mm256_sqrt_ps(len2);
    // c = d * ((len - reach) / (len * wsum)), da = c * wa, db = -(c * wb)
    const __m256 q = _mm256_div_ps(_mm256_sub_ps(len, reach), _mm256_mul_ps(len, wsum));
    const __m256 cx = _mm256_mul_ps(dx, q), cy = _mm256_mul_ps(dy, q), cz = _mm256_mul_ps(dz, q);
    // Moved: a structural edge (kind 0), wsum > 0, len2 > reach^2, not stretched to its tear length
    // (shouldTear: len > rest x tear_factor where structural edges tear)
    const __m256 structural = _mm256_cmp_ps(
        _mm256_cvtepi32_ps(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(kind + k))), zero, _CMP_EQ_OQ);
    __m256 ok = _mm256_and_ps(
        structural, _mm256_and_ps(_mm256_cmp_ps(wsum, zero, _CMP_GT_OQ), _mm256_cmp_ps(len2, reach2, _CMP_GT_OQ)));
    if (limit.tears)
      ok = _mm256_andnot_ps(_mm256_cmp_ps(len, _mm256_mul_ps(_mm256_loadu_ps(rest + k), tear_factor), _CMP_GT_OQ), ok);
    storeEnds(e, _mm256_and_ps(_mm256_mul_ps(cx, wa), ok), _mm256_and_ps(_mm256_mul_ps(cy, wa), ok),
              _mm256_and_ps(_mm256_mul_ps(cz, wa), ok), _mm256_and_ps(_mm256_xor_ps(_mm256_mul_ps(cx, wb), sign), ok),
              _mm256_and_ps(_mm256_xor_ps(_mm256_mul_ps(cy, wb), sign), ok),
              _mm256_and_ps(_mm256_xor_ps(_mm256_mul_ps(cz, wb), sign), ok));
  }
  return k;
}

namespace {

using V = __m256;
inline V add(V a, V b) { return _mm256_add_ps(a, b); }
inline V sub(V a, V b) { return _mm256_sub_ps(a, b); }
inline V mul(V a, V b) { return _mm256_mul_ps(a, b); }
inline V div(V a, V b) { return _mm256_div_ps(a, b); }
inline V all(float v) { return _mm256_set1_ps(v); }
inline V gt(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_GT_OQ); }
inline V lt(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_LT_OQ); }
inline V le(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_LE_OQ); }
inline V pick(V mask, V yes, V no) { return _mm256_blendv_ps(no, yes, mask); }
inline V neg(V a) { return _mm256_xor_ps(a, all(-0.0f)); }

struct V3 {
  V x, y, z;
};
inline V3 sub3(V3 a, V3 b) { return {sub(a.x, b.x), sub(a.y, b.y), sub(a.z, b.z)}; }
inline V3 scale3(V3 a, V s) { return {mul(a.x, s), mul(a.y, s), mul(a.z, s)}; }
// dot3 and cross3 of exact_math.h: (x x + y y) + z z; each component one difference of products
inline V dot3(V3 a, V3 b) { return add(add(mul(a.x, b.x), mul(a.y, b.y)), mul(a.z, b.z)); }
inline V3 cross3(V3 a, V3 b) {
  return {sub(mul(a.y, b.z), mul(a.z, b.y)), sub(mul(a.z, b.x), mul(a.x, b.z)), sub(mul(a.x, b.y), mul(a.y, b.x))};
}

// simAtan2 of exact_math.h, both branches in every lane (the same constants and operations)
V atan2(V y, V x) {
  const V abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7FFFFFFF));
  const V ax = _mm256_and_ps(x, abs_mask), ay = _mm256_and_ps(y, abs_mask);
  const V big = _mm256_max_ps(ax, ay), small = _mm256_min_ps(ax, ay);
  const V turn = gt(small, mul(all(0.41421356f), big));
  const V t = div(pick(turn, sub(small, big), small), pick(turn, add(small, big), big));
  const V base = pick(turn, all(0.78539816f), all(0.0f));
  const V z = mul(t, t);
  V p = sub(mul(all(0.0805374449538f), z), all(0.138776856032f));
  p = sub(mul(add(mul(p, z), all(0.199777106478f)), z), all(0.333329491539f));
  V a = add(base, add(mul(mul(p, z), t), t));
  a = pick(gt(ay, ax), sub(all(1.57079633f), a), a);
  a = pick(lt(x, all(0.0f)), sub(all(3.14159265f), a), a);
  a = pick(lt(y, all(0.0f)), neg(a), a);
  return pick(gt(big, all(0.0f)), a, all(0.0f));
}

// wrapAngle of exact_math.h
V wrap(V a) {
  const V pi = all(3.14159265f), two_pi = all(2.0f * 3.14159265f);
  return pick(gt(a, pi), sub(a, two_pi), pick(le(a, neg(pi)), add(a, two_pi), a));
}

// Eight rows of 4 floats (p[l] + 4 * index[l]) as x, y, z, w registers, and back.
struct Rows {
  float* at[8];
  V row[4]; // the rows as loaded (two per register)
  V x, y, z, w;
};
inline void load(Rows& r, float* base, const uint32_t* index, uint32_t stride) {
  for (uint32_t l = 0; l < 8; ++l) r.at[l] = base + 4 * size_t(index[stride * l]);
  for (uint32_t q = 0; q < 4; ++q) r.row[q] = loadRows(r.at[q], r.at[q + 4]);
  r.x = r.row[0], r.y = r.row[1], r.z = r.row[2], r.w = r.row[3];
  transpose(r.x, r.y, r.z, r.w);
}
// Stores each row plus (dx, dy, dz, 0) per lane
inline void storeAdded(Rows& r, V dx, V dy, V dz) {
  V dw = _mm256_setzero_ps();
  transpose(dx, dy, dz, dw);
  const V d[4] = {dx, dy, dz, dw};
  for (uint32_t q = 0; q < 4; ++q) storeRows(r.at[q], r.at[q + 4], add(r.row[q], d[q]));
}

// The angle part of hingeAngle (xpbd.h): the edge, the normals and the angle of each lane, and
// whether the hinge is valid
struct Frame {
  V3 e, au, na, nb;
  V e2, na2, nb2, el, angle, valid;
};
Frame frameOf(const V3& pu, const V3& pv, const V3& pa, const V3& pb) {
  Frame f;
  f.e = sub3(pv, pu);
  f.au = sub3(pa, pu);
  f.na = cross3(f.e, f.au);
  f.nb = cross3(sub3(pu, pv), sub3(pb, pv));
  f.e2 = dot3(f.e, f.e);
  f.na2 = dot3(f.na, f.na);
  f.nb2 = dot3(f.nb, f.nb);
  const V tiny = mul(mul(all(1e-8f), f.e2), f.e2);
  f.valid = _mm256_and_ps(gt(f.e2, all(1e-30f)), _mm256_and_ps(gt(f.na2, tiny), gt(f.nb2, tiny)));
  f.valid = _mm256_and_ps(f.valid, _mm256_and_ps(lt(f.na2, all(1e30f)), lt(f.nb2, all(1e30f))));
  f.el = _mm256_sqrt_ps(f.e2);
  f.angle = atan2(dot3(cross3(f.nb, f.na), f.e), mul(dot3(f.na, f.nb), f.el));
  return f;
}

} // namespace

uint32_t creaseHinges(float* pos, float* state, const uint32_t* corners, const uint32_t* torn, float yield0,
                      float hardening, uint32_t begin, uint32_t end) {
  uint32_t k = begin;
  for (; k + 8 <= end; k += 8) {
    Rows u, v, a, b;
    load(u, pos, corners + 4 * size_t(k) + 0, 4);
    load(v, pos, corners + 4 * size_t(k) + 1, 4);
    load(a, pos, corners + 4 * size_t(k) + 2, 4);
    load(b, pos, corners + 4 * size_t(k) + 3, 4);
    const Frame f = frameOf({u.x, u.y, u.z}, {v.x, v.y, v.z}, {a.x, a.y, a.z}, {b.x, b.y, b.z});
    alignas(32) uint32_t whole[8];
    for (uint32_t l = 0; l < 8; ++l) whole[l] = torn[k + l] == 0u ? ~0u : 0u;
    // creaseReturn on the rest angle (x) and added yield (y) of the hinges k .. k + 7
    const uint32_t seq[8] = {k, k + 1, k + 2, k + 3, k + 4, k + 5, k + 6, k + 7};
    Rows st;
    load(st, state, seq, 1);
    const V d = wrap(sub(f.angle, st.x));
    const V abs_d = _mm256_and_ps(d, _mm256_castsi256_ps(_mm256_set1_epi32(0x7FFFFFFF)));
    const V over = sub(abs_d, add(all(yield0), st.y));
    V moves = _mm256_and_ps(f.valid, _mm256_load_ps(reinterpret_cast<const float*>(whole)));
    moves = _mm256_and_ps(moves, _mm256_and_ps(gt(all(yield0), all(0.0f)), gt(over, all(0.0f))));
    const V step = div(over, add(all(1.0f), all(hardening)));
    const V x = wrap(add(st.x, pick(lt(d, all(0.0f)), neg(step), step)));
    const V y = add(st.y, mul(all(hardening), step));
    alignas(32) float xs[8], ys[8];
    _mm256_store_ps(xs, pick(moves, x, st.x));
    _mm256_store_ps(ys, pick(moves, y, st.y));
    for (uint32_t l = 0; l < 8; ++l) {
      state[4 * size_t(k + l)] = xs[l];
      state[4 * size_t(k + l) + 1] = ys[l];
    }
  }
  return k;
}

uint32_t projectHinges(float* pos, float* state, const HingeSlots& slots, uint32_t begin, uint32_t end) {
  uint32_t k = begin;
  for (; k + 8 <= end; k += 8) {
    // Lane l is slot k + l (load puts rows 0-3 in the low half, 4-7 in the high half)
    alignas(32) uint32_t lane_hinge[8];
    for (uint32_t l = 0; l < 8; ++l) lane_hinge[l] = slots.hinge[k + l];
    uint32_t corner[4][8]; // corner j of each lane's hinge
    for (uint32_t l = 0; l < 8; ++l)
      for (uint32_t j = 0; j < 4; ++j) corner[j][l] = slots.corners[4 * size_t(lane_hinge[l]) + j];
    Rows u, v, a, b, st;
    load(u, pos, corner[0], 1);
    load(v, pos, corner[1], 1);
    load(a, pos, corner[2], 1);
    load(b, pos, corner[3], 1);
    load(st, state, lane_hinge, 1);
    // hingeAngle
    const V3 pu{u.x, u.y, u.z}, pv{v.x, v.y, v.z}, pa{a.x, a.y, a.z}, pb{b.x, b.y, b.z};
    const Frame f = frameOf(pu, pv, pa, pb);
    const V3 &e = f.e, &au = f.au, &na = f.na, &nb = f.nb;
    const V &e2 = f.e2, &na2 = f.na2, &nb2 = f.nb2, &el = f.el, &angle = f.angle, &valid = f.valid;
    const V3 ga = scale3(na, div(el, na2)), gb = scale3(nb, div(el, nb2));
    const V inv_e2 = div(all(1.0f), e2);
    const V sa = mul(dot3(au, e), inv_e2), sb = mul(dot3(sub3(pb, pu), e), inv_e2);
    const V oa = sub(all(1.0f), sa), ob = sub(all(1.0f), sb);
    const V3 gu{neg(add(mul(ga.x, oa), mul(gb.x, ob))), neg(add(mul(ga.y, oa), mul(gb.y, ob))),
                neg(add(mul(ga.z, oa), mul(gb.z, ob)))};
    const V3 gv{neg(add(mul(ga.x, sa), mul(gb.x, sb))), neg(add(mul(ga.y, sa), mul(gb.y, sb))),
                neg(add(mul(ga.z, sa), mul(gb.z, sb)))};
    // solveHinge, with the edge or diagonal compliance of each lane, from a zero multiplier
    alignas(32) float lane_alpha[8];
    for (uint32_t l = 0; l < 8; ++l)
      lane_alpha[l] = lane_hinge[l] >= slots.first_diagonal ? 0.5f * slots.alpha : slots.alpha;
    const V alpha = _mm256_load_ps(lane_alpha);
    const V c = wrap(sub(angle, st.x));
    const V denom = add(
        add(add(add(mul(u.w, dot3(gu, gu)), mul(v.w, dot3(gv, gv))), mul(a.w, dot3(ga, ga))), mul(b.w, dot3(gb, gb))),
        alpha);
    const V ok = _mm256_and_ps(valid, gt(denom, all(0.0f)));
    const V dl = div(sub(neg(c), mul(alpha, all(0.0f))), denom);
    auto step = [&](Rows& r, const V3& g) {
      const V s = mul(dl, r.w);
      storeAdded(r, _mm256_and_ps(mul(g.x, s), ok), _mm256_and_ps(mul(g.y, s), ok), _mm256_and_ps(mul(g.z, s), ok));
    };
    step(u, gu);
    step(v, gv);
    step(a, ga);
    step(b, gb);
  }
  return k;
}

} // namespace tender::avx
