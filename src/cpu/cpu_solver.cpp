#include "cpu_solver.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "worker_pool.h"
#if defined(TENDER_CPU_AVX)
#include "kernels_avx.h"
#endif

namespace tender {

using namespace shaderio;

namespace {

// Smallest share of a loop worth handing to another thread (elements). Below it the hand-off
// (about a microsecond) costs more than the work saved.
constexpr uint32_t kGrainParticles = 4096;   // integrate, floor, hash, reset: a few ns per particle
constexpr uint32_t kGrainConstraints = 1024; // projection of one colour, tear marking: ~2 ns each
constexpr uint32_t kGrainCollide = 256;      // collision gather: ~100 ns per particle
constexpr uint32_t kCollideChunksPerWorker = 4;
// Below this many particles a whole substep takes tens of microseconds, and sharing its loops
// costs more in hand-offs than it saves: every loop runs on the calling thread.
constexpr uint32_t kSmallSheet = 4096;

// Extra slots after the sorted position arrays and the adjacency list, so 4-wide loads never
// leave them.
constexpr uint32_t kSortedPad = 4, kAdjacencyPad = 16;

// For each 4-bit hit mask: the indices of its set lanes packed to the front, then the hit count.
alignas(16) constexpr auto kPackedLanes = [] {
  std::array<std::array<uint32_t, 8>, 16> t{};
  for (uint32_t mask = 0; mask < 16; ++mask)
    for (uint32_t lane = 0; lane < 4; ++lane)
      if ((mask >> lane) & 1u) t[mask][t[mask][4]++] = lane;
  return t;
}();

// The sorted adjacency list of one particle, for the membership tests of its collision hits.
// Lists of up to 16 entries sit in four registers (the unused lanes hold ~0u, never a particle),
// so a test is a few compares with no branch on the data.
class Adjacency {
public:
  Adjacency(const uint32_t* adj, uint32_t count) : adj_(adj), count_(count) {
#if defined(__SSE2__)
    if (count <= 16) {
      const __m128i last = _mm_set1_epi32(int(count) - 1);
      for (int g = 0; g < 4; ++g) {
        const __m128i lane = _mm_setr_epi32(4 * g, 4 * g + 1, 4 * g + 2, 4 * g + 3);
        const __m128i entries = _mm_loadu_si128(reinterpret_cast<const __m128i*>(adj + 4 * g));
        q_[g] = _mm_or_si128(entries, _mm_cmpgt_epi32(lane, last));
      }
    }
#endif
  }

  bool contains(uint32_t j) const {
#if defined(__SSE2__)
    if (count_ <= 16) {
      const __m128i key = _mm_set1_epi32(int(j));
      const __m128i eq = _mm_or_si128(_mm_or_si128(_mm_cmpeq_epi32(q_[0], key), _mm_cmpeq_epi32(q_[1], key)),
                                      _mm_or_si128(_mm_cmpeq_epi32(q_[2], key), _mm_cmpeq_epi32(q_[3], key)));
      return _mm_movemask_epi8(eq) != 0;
    }
#endif
    return std::binary_search(adj_, adj_ + count_, j);
  }

private:
  const uint32_t* adj_;
  uint32_t count_;
#if defined(__SSE2__)
  __m128i q_[4];
#endif
};

template <typename T>
uint64_t bytesOf(const std::vector<T>& v) {
  return uint64_t(v.capacity()) * sizeof(T);
}

} // namespace

CpuSolver::CpuSolver(CpuOptions options) : options_(options), pool_(std::make_unique<WorkerPool>(options.threads)) {
#if defined(TENDER_CPU_AVX)
  avx_ = avx::available();
#endif
}

// The constraints of each colour, reordered by their first particle, into split arrays for the
// SIMD loops. Constraints of one colour share no particle, so their order within the colour
// changes no result; this one makes the share of each worker a band of the sheet (the colours of
// the greedy colouring mix kinds, each in row order), so a worker keeps the same particles in its
// cache from colour to colour.
void CpuSolver::splitConstraints() {
  const size_t m = constraints_.size();
  std::vector<uint32_t> order(m);
  for (uint32_t k = 0; k < m; ++k) order[k] = k;
  auto first = [&](uint32_t k) { return std::min(constraints_[k].a, constraints_[k].b); };
  for (const ColorRange& range : colors_)
    std::stable_sort(order.begin() + range.first, order.begin() + range.first + range.count,
                     [&](uint32_t x, uint32_t y) { return first(x) < first(y); });
  con_a_.resize(m);
  con_b_.resize(m);
  con_kind_.resize(m);
  con_id_.resize(m);
  con_rest_.resize(m);
  for (size_t k = 0; k < m; ++k) {
    const Constraint& c = constraints_[order[k]];
    con_a_[k] = c.a;
    con_b_[k] = c.b;
    con_kind_[k] = c.kind_id & SIM_KIND_MASK;
    con_id_[k] = c.kind_id >> SIM_KIND_BITS;
    con_rest_[k] = c.rest;
  }
}

CpuSolver::~CpuSolver() = default;

uint32_t CpuSolver::threadCount() const { return pool_->size(); }

void CpuSolver::upload(const SheetTopology& topo) {
  topo_ = &topo;
  const uint32_t n = topo.particleCount();
  small_sheet_ = n < kSmallSheet;
  rest_ = topo.rest_pos;
  uv_ = topo.uv;
  pos_.resize(n);
  for (uint32_t i = 0; i < n; ++i) pos_[i] = glm::vec4(glm::vec3(rest_[i]), rest_[i].w > 0.5f ? 0.0f : 1.0f);
  prev_ = pos_;
  normal_.assign(n, glm::vec4(0.0f, 0.0f, 1.0f, 0.0f));
  delta_.assign(n, glm::vec4(0.0f));
  reset_from_ = pos_;
  constraints_ = topo.constraints;
  colors_ = topo.colors;
  splitConstraints();
  torn_.assign(topo.constraintCount(), 0u);
  triangles_ = topo.triangles;
  triangle_count_ = topo.triangleCount();
  adj_offsets_ = topo.adj_offsets;
  adj_list_ = topo.adj_list;
  adj_list_.resize(adj_list_.size() + kAdjacencyPad, ~0u);
  cell_count_.assign(topo.hash_size, 0u);
  cell_start_.assign(topo.hash_size + 1, 0u);
  cell_particles_.assign(n, 0u);
  particle_slot_.assign(n, 0u);
  particle_cell_.assign(n, 0u);
  particle_coord_.assign(n, glm::ivec4(0));
  sorted_x_.assign(n + kSortedPad, 0.0f);
  sorted_y_.assign(n + kSortedPad, 0.0f);
  sorted_z_.assign(n + kSortedPad, 0.0f);
  sorted_coord_.assign(n, glm::ivec4(0));
  near_list_.assign(options_.collision_lists ? size_t(SIM_NEAR_STRIDE) * n : 0, 0u);
  near_base_.assign(options_.collision_lists ? n : 0, glm::vec3(0.0f));
  near_state_ = glm::uvec4(0u);
  delta_by_particle_ = false;
}

void CpuSolver::integrate(const SimUniforms& u, uint32_t s) {
  const float dt2 = u.dt * u.dt;
  const vec4 wind = u.wind[s], twist = u.wind_twist[s];
  const vec4 target = u.grab_target[s], grab_prev = u.grab_prev[s];
  pool_->parallelFor(uint32_t(pos_.size()), grain(kGrainParticles), [&](uint32_t begin, uint32_t end) {
    vec4* pos = pos_.data();
    vec4* prev = prev_.data();
    const vec4* rest = rest_.data();
    const vec2* uv = uv_.data();
    for (uint32_t i = begin; i < end; ++i) {
      const VerletState st = integrateParticle(pos[i], prev[i], rest[i], uv[i].x, i == u.grab_index, target, grab_prev,
                                               u.flags, u.gravity, wind, twist, u.damping, dt2);
      pos[i] = st.pos;
      prev[i] = st.prev;
    }
  });
}

// Projects constraints [begin, end) of one colour. No two of them share a particle, so eight
// (AVX) or four (SSE) are solved at once with the exact operations of solveDistance (same order,
// same rounding).
void CpuSolver::projectRange(const float stiffness[4], uint32_t begin, uint32_t end) {
  vec4* p = pos_.data();
  const uint32_t *ca = con_a_.data(), *cb = con_b_.data(), *kind = con_kind_.data();
  const float* rest = con_rest_.data();
  uint32_t k = begin;
#if defined(TENDER_CPU_AVX)
  if (avx_) k = avx::projectColor(&p[0].x, ca, cb, rest, kind, stiffness, begin, end);
#endif
#if defined(__SSE2__)
  const __m128 zero = _mm_setzero_ps(), tiny = _mm_set1_ps(1e-9f), sign = _mm_set1_ps(-0.0f);
  for (; k + 4 <= end; k += 4) {
    float *a0 = &p[ca[k]].x, *a1 = &p[ca[k + 1]].x, *a2 = &p[ca[k + 2]].x, *a3 = &p[ca[k + 3]].x;
    float *b0 = &p[cb[k]].x, *b1 = &p[cb[k + 1]].x, *b2 = &p[cb[k + 2]].x, *b3 = &p[cb[k + 3]].x;
    const __m128 pa0 = _mm_loadu_ps(a0), pa1 = _mm_loadu_ps(a1), pa2 = _mm_loadu_ps(a2), pa3 = _mm_loadu_ps(a3);
    const __m128 pb0 = _mm_loadu_ps(b0), pb1 = _mm_loadu_ps(b1), pb2 = _mm_loadu_ps(b2), pb3 = _mm_loadu_ps(b3);
    // Transpose to one register per component.
    __m128 ax = pa0, ay = pa1, az = pa2, aw = pa3;
    _MM_TRANSPOSE4_PS(ax, ay, az, aw);
    __m128 bx = pb0, by = pb1, bz = pb2, bw = pb3;
    _MM_TRANSPOSE4_PS(bx, by, bz, bw);
    // d = b - a; len = sqrt(dot(d, d)) with dot = (x*x + y*y) + z*z
    const __m128 dx = _mm_sub_ps(bx, ax), dy = _mm_sub_ps(by, ay), dz = _mm_sub_ps(bz, az);
    const __m128 len = _mm_sqrt_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz)));
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
    // Back to one register per particle (w correction 0), then p += correction.
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
#endif
  for (; k < end; ++k) {
    PairDelta d = solveDistance(p[ca[k]], p[cb[k]], rest[k], stiffness[kind[k]]);
    p[ca[k]] += vec4(d.da, 0.0f);
    p[cb[k]] += vec4(d.db, 0.0f);
  }
}

void CpuSolver::project(const SimUniforms& u, uint32_t iterations) {
  const float stiffness[4] = {u.stiffness.x, u.stiffness.y, u.stiffness.z, u.stiffness.w};
  const uint32_t colors = uint32_t(colors_.size());
  if (colors == 0) return;
  uint32_t largest = 0;
  for (const ColorRange& range : colors_) largest = std::max(largest, range.count);
  const uint32_t chunks = pool_->chunksFor(largest, grain(kGrainConstraints));
  // Gauss-Seidel over colours: one phase per colour, as many iterations per job as fit.
  const uint32_t per_job = std::max(1u, WorkerPool::kMaxPhases / colors);
  for (uint32_t it = 0; it < iterations; it += per_job)
    pool_->runPhases(std::min(per_job, iterations - it) * colors, chunks, [&](uint32_t phase, uint32_t chunk) {
      const ColorRange& range = colors_[phase % colors];
      const uint32_t begin = WorkerPool::chunkBound(range.count, chunks, chunk);
      const uint32_t end = WorkerPool::chunkBound(range.count, chunks, chunk + 1);
      projectRange(stiffness, range.first + begin, range.first + end);
    });
}

void CpuSolver::buildHash(const SimUniforms& u) {
  const uint32_t n = uint32_t(pos_.size());
  const uint32_t g = grain(kGrainParticles);
  // Cell and bucket of every particle
  pool_->parallelFor(n, g, [&](uint32_t begin, uint32_t end) {
    for (uint32_t i = begin; i < end; ++i) {
      const ivec3 c = cellOf(vec3(pos_[i]), u.inv_cell);
      particle_coord_[i] = ivec4(c, 0);
      particle_cell_[i] = hashCell(c, u.hash_mask);
    }
  });
  // Count (the counts are all zero here: the scan clears them)
  uint32_t* count = cell_count_.data();
  const uint32_t* cell = particle_cell_.data();
  for (uint32_t i = 0; i < n; ++i) count[cell[i]]++;
  // Exclusive scan, shifted by one: start[h + 1] is the scatter's cursor in bucket h, and ends as
  // the start of bucket h + 1.
  uint32_t sum = 0;
  uint32_t* start = cell_start_.data();
  start[0] = 0;
  for (size_t h = 0, buckets = cell_count_.size(); h < buckets; ++h) {
    start[h + 1] = sum;
    sum += count[h];
    count[h] = 0;
  }
  // Scatter in index order, so the particles of a bucket stay sorted by index
  uint32_t *sorted = cell_particles_.data(), *slot = particle_slot_.data();
  for (uint32_t i = 0; i < n; ++i) {
    slot[i] = start[cell[i] + 1]++;
    sorted[slot[i]] = i;
  }
  // Gather positions and cells in bucket order, for the collision pass
  pool_->parallelFor(n, g, [&](uint32_t begin, uint32_t end) {
    for (uint32_t k = begin; k < end; ++k) {
      const uint32_t j = cell_particles_[k];
      sorted_x_[k] = pos_[j].x;
      sorted_y_[k] = pos_[j].y;
      sorted_z_[k] = pos_[j].z;
      sorted_coord_[k] = particle_coord_[j];
    }
  });
}

// Collision gather for the particles in hash slots [begin, end). Each particle sums the
// repulsion of its neighbours in the same order as the GPU: cells in dz, dy, dx order, the
// particles of a bucket in ascending index. With `build`, the unconnected particles within
// `search` also go to its candidate list (ascending).
bool CpuSolver::collideRange(const SimUniforms& u, uint32_t begin, uint32_t end, float search, bool build) {
  const float r = u.collision_radius, r2 = r * r, search2 = search * search;
  bool fits = true;
  const float *sx = sorted_x_.data(), *sy = sorted_y_.data(), *sz = sorted_z_.data();
  const uint32_t* slots = cell_particles_.data();
  const ivec4* coords = sorted_coord_.data();
  const uint32_t* start = cell_start_.data();

  // Buckets of the 27 cells around the current cell (dz, dy, dx order), looked up when first
  // needed and reused while the cell repeats.
  uint32_t bucket_first[27], bucket_last[27];
  ivec4 bucket_cell[27];
  ivec3 cached_cell(0);
  bool cached = false;
  uint32_t known = 0;    // bit b: bucket b is looked up for the current cell
  uint32_t nonempty = 0; // bit b: bucket b holds particles (among the known)
  // A neighbour cell on one side can hold a particle within `search` only when the particle is
  // closer than that to that side of its own cell (`search` never exceeds a cell). The test is
  // in cell units with a generous margin, so no contributing cell is ever skipped.
  const float reach = search * u.inv_cell + 1e-3f;
  // Bucket masks (bit dz*9 + dy*3 + dx, offsets +1) selected by the needed -1/0/+1 sides of an axis.
  static constexpr auto kAxisMasks = [] {
    std::array<std::array<uint32_t, 8>, 3> m{};
    for (uint32_t sides = 0; sides < 8; ++sides)
      for (uint32_t b = 0; b < 27; ++b) {
        if ((sides >> (b % 3)) & 1u) m[0][sides] |= 1u << b;
        if ((sides >> (b / 3 % 3)) & 1u) m[1][sides] |= 1u << b;
        if ((sides >> (b / 9)) & 1u) m[2][sides] |= 1u << b;
      }
    return m;
  }();
  // Slots within the radius, in summation order, with their bucket; filled without branches.
  constexpr uint32_t kHitCapacity = 64;
  uint32_t hit_slot[kHitCapacity + 4];
  uint8_t hit_bucket[kHitCapacity + 4];

  for (uint32_t k = begin; k < end; ++k) {
    const uint32_t i = slots[k];
    const vec3 pi(sx[k], sy[k], sz[k]);
    const ivec3 ci(coords[k]);
    if (!cached || ci != cached_cell) {
      cached_cell = ci;
      cached = true;
      known = nonempty = 0;
    }
    // The buckets this particle visits: on a side within reach on every axis (all three sides
    // of an axis when unsure), and non-empty.
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
      bucket_first[b] = start[h];
      bucket_last[b] = start[h + 1];
      bucket_cell[b] = ivec4(c, 0);
      nonempty |= start[h] < start[h + 1] ? 1u << b : 0u;
    }
    known |= visit;
    visit &= nonempty;
    const Adjacency adjacency(adj_list_.data() + adj_offsets_[i], adj_offsets_[i + 1] - adj_offsets_[i]);
    vec3 sum(0.0f);
    uint32_t hit_count = 0;
    uint32_t* list = build ? near_list_.data() + size_t(SIM_NEAR_STRIDE) * i : nullptr;
    uint32_t listed = 0;
    // Sums the hits so far (and lists them). Skips the particle itself (slot k), particles of
    // other cells sharing a bucket (each is counted from its own cell) and connected particles.
    auto flush = [&] {
      for (uint32_t t = 0; t < hit_count; ++t) {
        const uint32_t m = hit_slot[t];
        if (m == k || coords[m] != bucket_cell[hit_bucket[t]] || adjacency.contains(slots[m])) continue;
        const vec3 pj(sx[m], sy[m], sz[m]);
        if (list) {
          if (listed < SIM_NEAR_CAPACITY) {
            uint32_t e = listed + 1;
            for (; e > 1 && list[e - 1] > slots[m]; --e) list[e] = list[e - 1];
            list[e] = slots[m];
          }
          ++listed;
        }
        const vec3 d = pi - pj;
        if (dot(d, d) < r2) sum += repulsion(pi, pj, r, u.collision_stiffness);
      }
      hit_count = 0;
    };
#if defined(__SSE2__)
    const __m128 px = _mm_set1_ps(pi.x), py = _mm_set1_ps(pi.y), pz = _mm_set1_ps(pi.z), vr2 = _mm_set1_ps(search2);
#endif
    while (visit) { // ascending bucket index: dz, dy, dx order
      const uint32_t b = uint32_t(__builtin_ctz(visit));
      visit &= visit - 1u;
      const uint32_t first = bucket_first[b], last = bucket_last[b];
      for (uint32_t m = first; m < last; m += 4) {
#if defined(__SSE2__)
        // d = pi - pj; the same dot(d, d) < r2 test as the scalar maths, four at a time
        const __m128 dx = _mm_sub_ps(px, _mm_loadu_ps(sx + m));
        const __m128 dy = _mm_sub_ps(py, _mm_loadu_ps(sy + m));
        const __m128 dz = _mm_sub_ps(pz, _mm_loadu_ps(sz + m));
        const __m128 d2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
        uint32_t hits = uint32_t(_mm_movemask_ps(_mm_cmplt_ps(d2, vr2)));
#else
        uint32_t hits = 0;
        for (uint32_t lane = 0; lane < 4 && m + lane < last; ++lane) {
          const vec3 d = pi - vec3(sx[m + lane], sy[m + lane], sz[m + lane]);
          hits |= dot(d, d) < search2 ? 1u << lane : 0u;
        }
#endif
        if (last - m < 4) hits &= (1u << (last - m)) - 1u;
#if defined(__SSE2__)
        // Append the hit lanes, packed to the front: four slots and buckets stored, the hits kept.
        const __m128i lanes = _mm_load_si128(reinterpret_cast<const __m128i*>(kPackedLanes[hits].data()));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(hit_slot + hit_count),
                         _mm_add_epi32(_mm_set1_epi32(int(m)), lanes));
        const uint32_t bucket4 = b * 0x01010101u;
        std::memcpy(hit_bucket + hit_count, &bucket4, 4);
        hit_count += kPackedLanes[hits][4];
#else
        for (uint32_t lane = 0; lane < 4; ++lane) {
          hit_slot[hit_count] = m + lane;
          hit_bucket[hit_count] = uint8_t(b);
          hit_count += (hits >> lane) & 1u;
        }
#endif
        if (hit_count > kHitCapacity) flush();
      }
    }
    flush();
    delta_[k] = vec4(sum, 0.0f);
    if (list) {
      list[0] = listed <= SIM_NEAR_CAPACITY ? listed : 0u;
      near_base_[i] = pi;
      fits = fits && listed <= SIM_NEAR_CAPACITY;
    }
  }
  return fits;
}

void CpuSolver::collide(const SimUniforms& u) {
  // Several shares per worker: the cost of a particle varies with the crowd around it.
  pool_->parallelFor(
      uint32_t(pos_.size()), grain(kGrainCollide),
      [&](uint32_t begin, uint32_t end) { collideRange(u, begin, end, u.collision_radius, false); },
      kCollideChunksPerWorker);
  delta_by_particle_ = false;
}

// Repulsion on particle i from its candidate list: the candidates closer than the radius, summed
// as the gather sums them, by neighbour cell and then by index (the list is ascending).
vec3 CpuSolver::listRepulsion(const SimUniforms& u, uint32_t i) const {
  const uint32_t* list = near_list_.data() + size_t(SIM_NEAR_STRIDE) * i;
  const uint32_t count = list[0];
  vec3 sum(0.0f);
  if (count == 0) return sum;
  const float r = u.collision_radius, r2 = r * r;
  const vec3 pi(pos_[i]);
  const ivec3 ci = cellOf(pi, u.inv_cell);
  uint32_t code[SIM_NEAR_CAPACITY]; // neighbour cell of each candidate within the radius; 27: none
  for (uint32_t e = 0; e < count; ++e) {
    const vec3 pj(pos_[list[e + 1]]);
    const vec3 d = pi - pj;
    const ivec3 o = cellOf(pj, u.inv_cell) - ci;
    const bool in_reach = dot(d, d) < r2 && std::abs(o.x) <= 1 && std::abs(o.y) <= 1 && std::abs(o.z) <= 1;
    code[e] = in_reach ? cellCode(o) : 27u;
  }
  for (uint32_t b = 0; b < 27; ++b)
    for (uint32_t e = 0; e < count; ++e)
      if (code[e] == b) sum += repulsion(pi, vec3(pos_[list[e + 1]]), r, u.collision_stiffness);
  return sum;
}

uint32_t CpuSolver::collideSubstep(const SimUniforms& u) {
  const uint32_t n = uint32_t(pos_.size());
  const float skin = options_.collision_lists ? listSkin(u.collision_radius, u.inv_cell) : 0.0f;
  const float search = u.collision_radius + skin;
  // Has a particle travelled too far for the lists?
  std::atomic<bool> travelled{false};
  if (listsCurrent(near_state_, skin, search)) {
    pool_->parallelFor(n, grain(kGrainParticles), [&](uint32_t begin, uint32_t end) {
      bool far = false;
      for (uint32_t i = begin; i < end; ++i) far = far || travelledTooFar(vec3(pos_[i]), near_base_[i], skin);
      if (far) travelled.store(true, std::memory_order_relaxed);
    });
  }
  const uint32_t mode = listMode(near_state_, travelled.load(), skin, search);
  std::atomic<bool> overflow{false};
  if (mode == SIM_NEAR_LISTS) {
    // Mostly empty lists: a few ns per particle, shared out like the per-particle passes
    pool_->parallelFor(
        n, grain(kGrainParticles),
        [&](uint32_t begin, uint32_t end) {
          for (uint32_t i = begin; i < end; ++i) delta_[i] = vec4(listRepulsion(u, i), 0.0f);
        },
        kCollideChunksPerWorker);
    delta_by_particle_ = true;
  } else {
    buildHash(u);
    const bool build = mode == SIM_NEAR_BUILD;
    pool_->parallelFor(
        n, grain(kGrainCollide),
        [&](uint32_t begin, uint32_t end) {
          if (!collideRange(u, begin, end, build ? search : u.collision_radius, build))
            overflow.store(true, std::memory_order_relaxed);
        },
        kCollideChunksPerWorker);
    delta_by_particle_ = false;
  }
  near_state_ = listNextState(near_state_, mode, overflow.load(), search);
  return mode;
}

void CpuSolver::floorPass(const SimUniforms& u) {
  const bool collide = (u.flags & SIM_FLAG_COLLISION) != 0u;
  pool_->parallelFor(uint32_t(pos_.size()), grain(kGrainParticles), [&](uint32_t begin, uint32_t end) {
    vec4* pos = pos_.data();
    vec4* prev = prev_.data();
    const vec4* delta = delta_.data();
    const uint32_t* slot = particle_slot_.data();
    for (uint32_t i = begin; i < end; ++i) {
      const vec3 d = collide ? vec3(delta[delta_by_particle_ ? i : slot[i]]) : vec3(0.0f);
      const VerletState st = floorParticle(pos[i], prev[i], d, u.flags, u.floor_y, u.restitution, u.friction);
      pos[i] = st.pos;
      prev[i] = st.prev;
    }
  });
}

// Marks the live constraints among array slots [begin, end) of the split arrays; returns how many
// tore. Four at a time, the length test of shouldTear with the same operations; the few lanes that
// pass it go through shouldTear itself.
uint32_t CpuSolver::markTearsRange(const SimUniforms& u, uint32_t begin, uint32_t end) {
  const vec4* p = pos_.data();
  const uint32_t *ca = con_a_.data(), *cb = con_b_.data(), *kind = con_kind_.data(), *id = con_id_.data();
  const float* rest = con_rest_.data();
  uint32_t torn = 0;
  auto check = [&](uint32_t k) {
    if (shouldTear(p[ca[k]], p[cb[k]], rest[k], kind[k], u.tear_factor, u.tear_kinds)) {
      torn_[id[k]] = 1u;
      ++torn;
    }
  };
  for (const ColorRange& range : colors_) {
    const uint32_t first = std::max(begin, range.first), last = std::min(end, range.first + range.count);
    uint32_t k = first;
#if defined(__SSE2__)
    const __m128 factor = _mm_set1_ps(u.tear_factor);
    for (; k + 4 <= last; k += 4) {
      __m128 ax = _mm_loadu_ps(&p[ca[k]].x), ay = _mm_loadu_ps(&p[ca[k + 1]].x);
      __m128 az = _mm_loadu_ps(&p[ca[k + 2]].x), aw = _mm_loadu_ps(&p[ca[k + 3]].x);
      __m128 bx = _mm_loadu_ps(&p[cb[k]].x), by = _mm_loadu_ps(&p[cb[k + 1]].x);
      __m128 bz = _mm_loadu_ps(&p[cb[k + 2]].x), bw = _mm_loadu_ps(&p[cb[k + 3]].x);
      _MM_TRANSPOSE4_PS(ax, ay, az, aw);
      _MM_TRANSPOSE4_PS(bx, by, bz, bw);
      // sqrt(dot(d, d)) > rest * tear_factor with d = b - a and dot = (x*x + y*y) + z*z
      const __m128 dx = _mm_sub_ps(bx, ax), dy = _mm_sub_ps(by, ay), dz = _mm_sub_ps(bz, az);
      const __m128 len =
          _mm_sqrt_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz)));
      const __m128 limit = _mm_mul_ps(_mm_loadu_ps(rest + k), factor);
      for (uint32_t over = uint32_t(_mm_movemask_ps(_mm_cmpgt_ps(len, limit))); over; over &= over - 1u)
        check(k + uint32_t(__builtin_ctz(over)));
    }
#endif
    for (; k < last; ++k) check(k);
  }
  return torn;
}

uint32_t CpuSolver::markTears(const SimUniforms& u) {
  if (u.tear_factor <= 0.0f) return 0;
  std::atomic<uint32_t> torn{0};
  pool_->parallelFor(uint32_t(constraints_.size()), grain(kGrainConstraints), [&](uint32_t begin, uint32_t end) {
    if (uint32_t t = markTearsRange(u, begin, end)) torn.fetch_add(t, std::memory_order_relaxed);
  });
  return torn.load();
}

void CpuSolver::compact() {
  for (ColorRange& range : colors_) {
    uint32_t w = range.first;
    for (uint32_t k = range.first; k < range.first + range.count; ++k)
      if (!torn_[constraints_[k].kind_id >> SIM_KIND_BITS]) constraints_[w++] = constraints_[k];
    // The split arrays lose the same constraints of the colour and keep their order.
    uint32_t v = range.first;
    for (uint32_t k = range.first; k < range.first + range.count; ++k)
      if (!torn_[con_id_[k]]) {
        con_a_[v] = con_a_[k];
        con_b_[v] = con_b_[k];
        con_kind_[v] = con_kind_[k];
        con_id_[v] = con_id_[k];
        con_rest_[v++] = con_rest_[k];
      }
    range.count = w - range.first;
  }
  const auto& edges = topo_->tri_edges;
  uint32_t w = 0;
  for (uint32_t k = 0; k < triangle_count_; ++k) {
    const glm::uvec2 e = edges[triangles_[k].w];
    if (!torn_[e.x] && !torn_[e.y]) triangles_[w++] = triangles_[k];
  }
  triangle_count_ = w;
}

void CpuSolver::resetPass(const SimUniforms& u) {
  pool_->parallelFor(uint32_t(pos_.size()), grain(kGrainParticles), [&](uint32_t begin, uint32_t end) {
    for (uint32_t i = begin; i < end; ++i) {
      const float w = inverseMass(rest_[i], false, u.flags);
      pos_[i] = vec4(mix(vec3(reset_from_[i]), vec3(rest_[i]), u.reset_alpha), w);
      prev_[i] = pos_[i];
    }
  });
}

void CpuSolver::tick(const SimUniforms& u) {
  if (u.reset_active) {
    resetPass(u);
    passes_per_tick_ = 1;
    return;
  }
  const bool collision = (u.flags & SIM_FLAG_COLLISION) != 0u;
  uint32_t passes = 0;
  for (uint32_t s = 0; s < u.substeps; ++s) {
    integrate(u, s);
    project(u, u.iterations);
    if (collision) collideSubstep(u);
    floorPass(u);
    if (markTears(u) > 0) compact();
    passes += 1 + u.iterations * uint32_t(colors_.size()) + (collision ? 2 : 0) + 2;
  }
  passes_per_tick_ = passes;
}

void CpuSolver::beginReset() {
  reset_from_ = pos_;
  constraints_ = topo_->constraints;
  colors_ = topo_->colors;
  splitConstraints();
  std::fill(torn_.begin(), torn_.end(), 0u);
  triangles_ = topo_->triangles;
  triangle_count_ = topo_->triangleCount();
}

void CpuSolver::computeNormals() {
  const uint32_t W = topo_->cols, H = topo_->rows;
  for (uint32_t j = 0; j < H; ++j)
    for (uint32_t i = 0; i < W; ++i) {
      const uint32_t l = j * W + (i > 0 ? i - 1 : i), r = j * W + (i + 1 < W ? i + 1 : i);
      const uint32_t up = (j > 0 ? j - 1 : j) * W + i, dn = (j + 1 < H ? j + 1 : j) * W + i;
      normal_[j * W + i] = vec4(gridNormal(vec3(pos_[l]), vec3(pos_[r]), vec3(pos_[up]), vec3(pos_[dn])), 0.0f);
    }
}

PickResult CpuSolver::pick(glm::vec3 o, glm::vec3 d, float radius) {
  PickResult best{};
  best.index = SIM_NONE;
  float best_d2 = radius * radius;
  for (uint32_t i = 0; i < pos_.size(); ++i) {
    vec2 r = rayPointDistance2(o, d, vec3(pos_[i]));
    if (r.x <= best_d2 && (best.index == SIM_NONE || r.x < best_d2)) {
      best.index = i;
      best.t = r.y;
      best_d2 = r.x;
    }
  }
  if (best.index != SIM_NONE) {
    best.d2 = floatBitsToUint(best_d2);
    best.pos = pos_[best.index];
  }
  return best;
}

void CpuSolver::readback(SimState& out) {
  out.pos = pos_;
  out.prev = prev_;
  out.normal = normal_;
  out.constraints = constraints_;
  out.colors = colors_;
  out.torn = torn_;
  out.triangles.assign(triangles_.begin(), triangles_.begin() + triangle_count_);
  out.triangle_count = triangle_count_;
}

uint64_t CpuSolver::memoryBytes() const {
  return bytesOf(pos_) + bytesOf(prev_) + bytesOf(rest_) + bytesOf(normal_) + bytesOf(delta_) + bytesOf(reset_from_) +
         bytesOf(uv_) + bytesOf(constraints_) + bytesOf(colors_) + bytesOf(torn_) + bytesOf(con_a_) + bytesOf(con_b_) +
         bytesOf(con_kind_) + bytesOf(con_id_) + bytesOf(con_rest_) + bytesOf(triangles_) + bytesOf(adj_offsets_) +
         bytesOf(adj_list_) + bytesOf(cell_count_) + bytesOf(cell_start_) + bytesOf(cell_particles_) +
         bytesOf(particle_slot_) + bytesOf(particle_cell_) + bytesOf(particle_coord_) + bytesOf(sorted_x_) +
         bytesOf(sorted_y_) + bytesOf(sorted_z_) + bytesOf(sorted_coord_) + bytesOf(near_list_) + bytesOf(near_base_);
}

} // namespace tender
