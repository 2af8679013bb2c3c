#include "cpu_contact.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <mutex>

#include <glm/gtc/quaternion.hpp>
#include <glm/gtx/component_wise.hpp>

#include "cpu_collision.h"
#include "worker_pool.h"

namespace tender {

using namespace shaderio;
using glm::ivec3;
using glm::uvec2;
using glm::uvec4;
using glm::vec3;

namespace {

/// Lowers `slot`, the bits of a non-negative float, to the bits of d2: such floats order as their
/// bits, so the smallest wins whatever the order of the calls.
void lower(uint32_t& slot, float d2) {
  std::atomic_ref<uint32_t> a(slot);
  const uint32_t v = std::bit_cast<uint32_t>(d2);
  uint32_t seen = a.load(std::memory_order_relaxed);
  while (v < seen && !a.compare_exchange_weak(seen, v, std::memory_order_relaxed)) {
  }
}

/// The cell of the contact grids that holds p: floor(p x inv_cell), clamped, with a floor of
/// integer conversions (floorf is a call without SSE 4.1). Any cell function that rises with its
/// point would do: which cells hold a box decides where the search looks, not what it finds.
inline int gridCoordinate(float x) {
  constexpr float kMost = 536870912.0f;
  x = x > -kMost ? (x < kMost ? x : kMost) : -kMost; // NaN to the lowest
  const int i = int(x);
  return i - (x < float(i) ? 1 : 0);
}
inline ivec3 gridCell(vec3 p, float inv_cell) {
  return ivec3(gridCoordinate(p.x * inv_cell), gridCoordinate(p.y * inv_cell), gridCoordinate(p.z * inv_cell));
}

/// Calls f(entry) once for each entry of `grid` from `first` on whose box overlaps the box [lo,
/// hi]: in the cell that holds the lowest corner of the two boxes' overlap (both boxes are in that
/// cell; a bucket holds an entry once, so no entry is met twice). That cell is the larger of the
/// two lowest corners' cells, component by component (gridCell rises with its point). A bucket's
/// entries rise (Grid::build), so it is read from its end down to `first`.
template <typename Grid, typename F>
void visitBox(const Grid& grid, vec3 lo, vec3 hi, float inv_cell, uint32_t first, F&& f) {
  const ivec3 a = gridCell(lo, inv_cell), b = gridCell(hi, inv_cell);
  for (int z = a.z; z <= b.z; ++z)
    for (int y = a.y; y <= b.y; ++y)
      for (int x = a.x; x <= b.x; ++x) {
        const ivec3 cell(x, y, z);
        const uint32_t h = hashCell(cell, grid.mask);
        for (uint32_t k = grid.start[h + 1]; k-- > grid.start[h];) {
          const auto& slot = grid.entry[k];
          if (slot.id < first) break;
          const vec3 elo = slot.lo, ehi = slot.hi;
          if (!(lo.x <= ehi.x && elo.x <= hi.x && lo.y <= ehi.y && elo.y <= hi.y && lo.z <= ehi.z && elo.z <= hi.z))
            continue;
          if (glm::max(a, slot.cell) == cell) f(slot.id);
        }
      }
}

float length2(vec3 a) { return dot3(a, a); }

/// The corner of a box whose components are gathered as orderedBits.
vec3 orderedCorner(glm::uvec3 o) { return vec3(orderedFloat(o.x), orderedFloat(o.y), orderedFloat(o.z)); }

bool less4(uvec4 a, uvec4 b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  if (a.z != b.z) return a.z < b.z;
  return a.w < b.w;
}

/// Calls look(k, found) for each k of [0, count) on the pool's threads (`shares` a worker) and
/// appends what each finds to `out`, in any order (the lists are sorted after).
template <typename Look>
void gatherPairs(WorkerPool& pool, uint32_t count, uint32_t grain, uint32_t shares, std::vector<uvec4>& out,
                 Look&& look) {
  std::mutex merge;
  pool.parallelFor(
      count, grain,
      [&](uint32_t begin, uint32_t end) {
        std::vector<uvec4> found;
        for (uint32_t k = begin; k < end; ++k) look(k, found);
        const std::lock_guard<std::mutex> lock(merge);
        out.insert(out.end(), found.begin(), found.end());
      },
      shares);
}

} // namespace

void CpuContact::Grid::build(const std::vector<vec3>& lo, const std::vector<vec3>& hi, float inv_cell, WorkerPool& pool,
                             uint32_t part_boxes) {
  const uint32_t n = uint32_t(lo.size());
  const uint32_t size = std::bit_ceil(std::max(2u * n, 16u));
  mask = size - 1;
  // The boxes in `parts` runs of consecutive ones, each counted and filled by one thread into its
  // own share of each bucket, the runs' shares in their order: the entries rise in every bucket
  // whatever the thread count
  const uint32_t parts = std::max(1u, std::min({pool.size(), kGridParts, n / part_boxes}));
  auto first = [&](uint32_t part) { return uint32_t(uint64_t(n) * part / parts); };
  fill.assign(size_t(parts) * size, 0);
  last.assign(size_t(parts) * size, ~0u);
  // Calls f(h) for the bucket of each cell box i spans, each bucket once (two cells of a box may
  // share one): `seen` holds the box that last went into each bucket
  auto buckets = [&](uint32_t i, uint32_t* seen, auto&& f) {
    const ivec3 a = gridCell(lo[i], inv_cell), b = gridCell(hi[i], inv_cell);
    for (int z = a.z; z <= b.z; ++z)
      for (int y = a.y; y <= b.y; ++y)
        for (int x = a.x; x <= b.x; ++x) {
          const uint32_t h = hashCell(ivec3(x, y, z), mask);
          if (seen[h] == i) continue;
          seen[h] = i;
          f(h);
        }
  };
  auto each = [&](auto&& visit) {
    pool.parallelFor(parts, 1, [&](uint32_t begin, uint32_t end) {
      for (uint32_t part = begin; part < end; ++part) {
        uint32_t *count = fill.data() + size_t(part) * size, *seen = last.data() + size_t(part) * size;
        for (uint32_t i = first(part); i < first(part + 1); ++i) visit(i, seen, count);
      }
    });
  };
  each([&](uint32_t i, uint32_t* seen, uint32_t* count) { buckets(i, seen, [&](uint32_t h) { ++count[h]; }); });
  // Each part's first slot in each bucket, after the parts before it
  start.resize(size + 1);
  uint32_t total = 0;
  for (uint32_t h = 0; h < size; ++h) {
    start[h] = total;
    for (uint32_t part = 0; part < parts; ++part) {
      const uint32_t k = fill[size_t(part) * size + h];
      fill[size_t(part) * size + h] = total;
      total += k;
    }
  }
  start[size] = total;
  entry.resize(total);
  std::fill(last.begin(), last.end(), ~0u);
  each([&](uint32_t i, uint32_t* seen, uint32_t* slot) {
    const Slot box{lo[i], i, hi[i], gridCell(lo[i], inv_cell)};
    buckets(i, seen, [&](uint32_t h) { entry[slot[h]++] = box; });
  });
}

void CpuContact::computeBounds(const std::vector<glm::vec4>& pos, const std::vector<glm::vec4>& prev,
                               const std::vector<uvec4>& triangles, uint32_t count, const SimUniforms& u, uint32_t s,
                               std::vector<float>& bound, std::vector<glm::vec4>& push) {
  const uint32_t n = uint32_t(pos.size());
  const float radius = u.contact.x, thickness = u.contact.z, scale = u.contact.w;
  bound.resize(n);
  push.resize(n);
  // What the GPU's contact_clear gathers, in orderedBits (the same bits in any order): the frame's
  // inputs (every particle's last step, lowest and highest, and their lowest start above the floor)
  // and the box of every particle's travel since the lists were built
  struct Gathered {
    glm::uvec3 lo{~0u}, hi{0u}, travel_lo{~0u}, travel_hi{0u};
    uint32_t lowest = std::bit_cast<uint32_t>(INFINITY);
  } all;
  const bool based = base_.size() == n;
  std::mutex merge;
  pool_.parallelFor(n, kGrainParticles, [&](uint32_t begin, uint32_t end) {
    Gathered g;
    for (uint32_t i = begin; i < end; ++i) {
      const vec3 step = vec3(pos[i]) - vec3(prev[i]), d = based ? vec3(pos[i]) - vec3(base_[i]) : vec3(0.0f);
      for (int c = 0; c < 3; ++c) {
        g.lo[c] = std::min(g.lo[c], orderedBits(step[c]));
        g.hi[c] = std::max(g.hi[c], orderedBits(step[c]));
        g.travel_lo[c] = std::min(g.travel_lo[c], orderedBits(d[c]));
        g.travel_hi[c] = std::max(g.travel_hi[c], orderedBits(d[c]));
      }
      const float height = pos[i].y - u.floor_y;
      g.lowest = std::min(g.lowest, std::bit_cast<uint32_t>(height > 0.0f ? height : 0.0f));
    }
    const std::lock_guard<std::mutex> lock(merge);
    all.lo = glm::min(all.lo, g.lo);
    all.hi = glm::max(all.hi, g.hi);
    all.travel_lo = glm::min(all.travel_lo, g.travel_lo);
    all.travel_hi = glm::max(all.travel_hi, g.travel_hi);
    all.lowest = std::min(all.lowest, g.lowest);
  });
  frame_ = all.lo.x > all.hi.x ? vec3(0.0f)
                               : contactFrame(orderedCorner(all.lo), orderedCorner(all.hi),
                                              std::bit_cast<float>(all.lowest), contactFrameScale(u.verlet, s));
  if (edges_key_ != count) {
    edges_.clear();
    for (uint32_t t = 0; t < count; ++t) {
      const uvec4 tri = triangles[t];
      for (uvec2 e : {uvec2(tri.x, tri.y), uvec2(tri.y, tri.z), uvec2(tri.z, tri.x)})
        edges_.push_back(uvec2(std::min(e.x, e.y), std::max(e.x, e.y)));
    }
    std::sort(edges_.begin(), edges_.end(), [](uvec2 a, uvec2 b) { return a.x != b.x ? a.x < b.x : a.y < b.y; });
    edges_.erase(std::unique(edges_.begin(), edges_.end()), edges_.end());
    edges_key_ = count;
    lists_ = false;
  }
  const float r = radius, r2 = r * r;
  // The pair lists hold every pair that can be closer than r while the particles' travel since
  // they were built stays within contactTravel of one point (listsOutgrown)
  const bool usable = lists_kept_ != Lists::Rebuilt && lists_ && list_radius_ == radius && based;
  const vec3 travel_lo = orderedCorner(all.travel_lo), travel_hi = orderedCorner(all.travel_hi);
  const bool finite = length2(travel_hi - travel_lo) < 1e30f;
  bool fresh = usable && !listsOutgrown(travel_lo, travel_hi, radius);
  // or the travels within it once the sheet's turn since is taken out (finite travels only)
  travel_.clear();
  if (usable && !fresh && finite) {
    const auto [lo, hi] = turnedTravel(pos);
    fresh = !listsOutgrown(lo, hi, radius);
    turns_ += fresh ? 1u : 0u;
    // or within it near each other, the clusters of the bases apart (clustersHold)
    if (!fresh && clustersHold(lo, hi, radius)) {
      fresh = true;
      ++held_;
    }
  }
  // or repairable around the particles that travelled beyond it
  // (while they hold no more than twice the pairs of the last build and an eighth of the particles:
  // a repair lists its particles' pairs from farther, contactRepairReach, and they stay until a
  // build; on a flat sheet that is every particle's nearest diagonal)
  const bool repairable = usable && lists_kept_ == Lists::Repaired && finite &&
                          vf_.size() + ee_.size() <= 2 * built_pairs_ + n / kRepairShare;
  if (!fresh && !(repairable && repairLists(pos, triangles, count, radius))) buildLists(pos, triangles, count, radius);
  sums_.assign(n, glm::ivec4(0));
  findCrossings(pos, triangles, count, s == 0 && (u.contact_check.x & SIM_CONTACT_CHECK_ALL) != 0u, thickness, scale);
  const uint32_t none = std::bit_cast<uint32_t>(r2);
  nearest2_.assign(n, lists_ ? none : 0u); // positions gone wrong (no lists): nothing moves
  auto at = [&](uint32_t i) { return vec3(pos[i]); };
  auto vf = [](vec3 p, vec3 a, vec3 b, vec3 c) { return pointTriangle(p, a, b, c); };
  auto ee = [](vec3 a, vec3 b, vec3 c, vec3 d) { return segmentSegment(a, b, c, d); };
  // Each pair closer than r lowers the bounds of its four particles; one closer than the thickness
  // pushes them apart (contactPush), summed in fixed point. Pairs with a free particle are left
  // out: the sheet untangles there as the repulsion alone lets it. Neither the minimum nor the
  // integer sums depend on the order of the pairs, so nothing depends on the thread count.
  auto nearest = [&](const std::vector<uvec4>& list, auto&& pair) {
    pool_.parallelFor(uint32_t(list.size()), kGrainConstraints, [&](uint32_t begin, uint32_t end) {
      for (uint32_t k = begin; k < end; ++k) {
        const uvec4 q = list[k];
        if (free_[q.x] | free_[q.y] | free_[q.z] | free_[q.w]) continue;
        const ContactPair c = pair(at(q.x), at(q.y), at(q.z), at(q.w));
        if (!(c.d2 < r2)) continue;
        for (uint32_t i : {q.x, q.y, q.z, q.w}) lower(nearest2_[i], c.d2);
        if (!(c.d2 < thickness * thickness)) continue;
        const glm::vec4 x[4] = {pos[q.x], pos[q.y], pos[q.z], pos[q.w]};
        for (uint32_t j = 0; j < 4; ++j)
          addFixed(sums_, q[j], contactPush(x[0], x[1], x[2], x[3], c, thickness, j), scale);
      }
    });
  };
  nearest(vf_, vf);
  nearest(ee_, ee);
  uint64_t contacts = 0;
  for (uint32_t i = 0; i < n; ++i) {
    contacts += nearest2_[i] < none ? 1u : 0u;
    bound[i] = free_[i] ? INFINITY : slideBound(std::bit_cast<float>(nearest2_[i]), radius, u.contact.y);
    push[i] =
        glm::vec4(contactPushWithin(contactAverage(sums_[i], scale), std::bit_cast<float>(nearest2_[i]), radius), 0.0f);
  }
  contacts_ = contacts;
}

// Each pair's half-spaces, weighed at `start` as computeBounds weighed it; `visit` sees each of its
// particles' (a pair once, from any thread: what it sums and lowers must not depend on the order)
// with the pair, its nearest points and the particle's place in it
template <class Visit>
void CpuContact::visitHalfSpaces(const std::vector<glm::vec4>& start, const SimUniforms& u, Visit&& visit) {
  const float radius = u.contact.x, fraction = u.contact.y;
  auto at = [&](uint32_t i) { return vec3(start[i]); };
  for (const bool edge : {false, true}) {
    const std::vector<uvec4>& list = edge ? ee_ : vf_;
    pool_.parallelFor(uint32_t(list.size()), kGrainConstraints, [&](uint32_t begin, uint32_t end) {
      for (uint32_t k = begin; k < end; ++k) {
        const uvec4 q = list[k];
        if (free_[q.x] | free_[q.y] | free_[q.z] | free_[q.w]) continue;
        const vec3 x0 = at(q.x), x1 = at(q.y), x2 = at(q.z), x3 = at(q.w);
        const ContactPair c = edge ? segmentSegment(x0, x1, x2, x3) : pointTriangle(x0, x1, x2, x3);
        if (!(c.d2 < radius * radius)) continue;
        for (uint32_t j = 0; j < 4; ++j) {
          const SlideHalf h = slideConstraint(x0, x1, x2, x3, c, edge, radius, fraction, j);
          if (h.h.w >= 0.0f) visit(q, c, edge, j, h);
        }
      }
    });
  }
}

void CpuContact::slide(const std::vector<glm::vec4>& start, const std::vector<glm::vec4>& pos, const SimUniforms& u,
                       std::vector<glm::vec4>& passed, std::vector<glm::vec4>& excess, std::vector<float>& share) {
  const uint32_t n = uint32_t(pos.size());
  const float scale = u.contact.w;
  passed.assign(n, glm::vec4(0.0f));
  excess.assign(n, glm::vec4(0.0f));
  share.assign(n, 1.0f);
  if (!lists_) return; // positions gone wrong: the bounds hold every particle
  auto pairs = [&](auto&& visit) { visitHalfSpaces(start, u, visit); };
  // What each step's excess passes on to the other primitive of its pairs
  sums_.assign(n, glm::ivec4(0));
  pairs([&](const uvec4& q, const ContactPair& c, bool edge, uint32_t j, const SlideHalf& h) {
    const vec3 e = slideExcess(h, vec3(pos[q[j]]) - (vec3(start[q[j]]) + frame_));
    if (e == vec3(0.0f)) return;
    for (uint32_t k = 0; k < 4; ++k)
      if (contactOpposite(j, k, edge) && pos[q[k]].w > 0.0f) addFixed(sums_, q[k], contactPassed(e, c, k), scale);
  });
  for (uint32_t i = 0; i < n; ++i) passed[i] = glm::vec4(contactAverage(sums_[i], scale), 0.0f);
  // The steps with what they are passed: their excess beyond their half-spaces, then the share
  auto step = [&](uint32_t i) {
    return passedPosition(pos[i], vec3(passed[i]), u.floor_y) - (vec3(start[i]) + frame_);
  };
  sums_.assign(n, glm::ivec4(0));
  pairs([&](const uvec4& q, const ContactPair&, bool, uint32_t j, const SlideHalf& h) {
    const vec3 e = slideExcess(h, step(q[j]));
    if (e != vec3(0.0f)) addFixed(sums_, q[j], e, scale);
  });
  for (uint32_t i = 0; i < n; ++i) excess[i] = glm::vec4(contactAverage(sums_[i], scale), 0.0f);
  std::vector<uint32_t>& bits = share_bits_;
  bits.assign(n, std::bit_cast<uint32_t>(1.0f));
  pairs([&](const uvec4& q, const ContactPair&, bool, uint32_t j, const SlideHalf& h) {
    const float s = slideShare(h, step(q[j]) + vec3(excess[q[j]]));
    if (s < 1.0f) lower(bits[q[j]], s);
  });
  for (uint32_t i = 0; i < n; ++i) share[i] = std::bit_cast<float>(bits[i]);
}

void CpuContact::listHalfSpaces(const std::vector<glm::vec4>& start, const SimUniforms& u) {
  // Counted, scanned, filled (a particle's in any order: room() takes their minimum)
  const uint32_t n = uint32_t(start.size());
  half_start_.assign(n + 1, 0u);
  if (!lists_) return;
  visitHalfSpaces(start, u, [&](const uvec4& q, const ContactPair&, bool, uint32_t j, const SlideHalf&) {
    std::atomic_ref<uint32_t>(half_start_[q[j] + 1]).fetch_add(1u, std::memory_order_relaxed);
  });
  for (uint32_t i = 0; i < n; ++i) half_start_[i + 1] += half_start_[i];
  half_.resize(half_start_[n]);
  half_slack_.resize(half_start_[n]);
  half_fill_.assign(half_start_.begin(), half_start_.end() - 1);
  visitHalfSpaces(start, u, [&](const uvec4& q, const ContactPair&, bool, uint32_t j, const SlideHalf& h) {
    const uint32_t k = std::atomic_ref<uint32_t>(half_fill_[q[j]]).fetch_add(1u, std::memory_order_relaxed);
    half_[k] = h.h;
    half_slack_[k] = h.slack;
  });
}

void CpuContact::addFixed(std::vector<glm::ivec4>& sums, uint32_t i, vec3 v, float scale) {
  const glm::ivec3 f = contactFixed(v, scale);
  int32_t* sum = &sums[i].x;
  for (uint32_t c = 0; c < 3; ++c) std::atomic_ref<int32_t>(sum[c]).fetch_add(f[c], std::memory_order_relaxed);
  std::atomic_ref<int32_t>(sum[3]).fetch_add(1, std::memory_order_relaxed);
}

void CpuContact::findCrossings(const std::vector<glm::vec4>& pos, const std::vector<uvec4>& triangles, uint32_t count,
                               bool all, float gap, float scale) {
  // Where the sheet already crosses itself (contact turned on in a sheet that crossed itself, or
  // a state that started so), no bound can undo it and bounds would hold it there: the particles
  // of the triangles that cross another go free until it untangles. Only what moved unbounded can
  // have crossed the sheet: the triangles crossingChecked names are tested against every triangle
  // whose box meets theirs.
  const uint32_t n = uint32_t(pos.size());
  was_free_.swap(free_);
  was_free_.resize(n, 0);
  free_.assign(n, 0);
  tangles_ = false;
  checked_.clear();
  if (!lists_) return; // positions gone wrong: nothing is looked for (nothing moves)
  for (uint32_t t = 0; t < count; ++t) {
    const uvec4 tri = triangles[t];
    if (crossingChecked(all, (was_free_[tri.x] | was_free_[tri.y] | was_free_[tri.z]) != 0)) checked_.push_back(t);
  }
  if (checked_.empty()) return;
  auto at = [&](uint32_t i) { return vec3(pos[i]); };
  boxTriangles(pos, triangles, count);
  float longest = 0.0f;
  for (uint32_t t = 0; t < count; ++t) longest = std::max(longest, glm::compMax(hi_[t] - lo_[t]));
  crossing_.assign(count, 0);
  auto test = [&](uint32_t t, uint32_t o) {
    const uvec4 a = triangles[t], b = triangles[o];
    if (a.x == b.x || a.x == b.y || a.x == b.z || a.y == b.x || a.y == b.y || a.y == b.z || a.z == b.x || a.z == b.y ||
        a.z == b.z)
      return;
    const vec3 x[6] = {at(a.x), at(a.y), at(a.z), at(b.x), at(b.y), at(b.z)};
    if (!trianglesCross(x[0], x[1], x[2], x[3], x[4], x[5])) return;
    std::atomic_ref<uint8_t>(crossing_[t]).store(1, std::memory_order_relaxed);
    std::atomic_ref<uint8_t>(crossing_[o]).store(1, std::memory_order_relaxed);
    // The pushes that untangle the pair, summed in fixed point with the contact's
    for (uint32_t k = 0; k < 6; ++k) {
      const vec3 push = untanglePush(x[0], x[1], x[2], x[3], x[4], x[5], gap, k);
      if (push != vec3(0.0f)) addFixed(sums_, k < 3 ? a[k] : b[k - 3], push, scale);
    }
  };
  const uint32_t checked = uint32_t(checked_.size());
  const float inv_cell = 1.0f / (1.01f * longest);
  if (uint64_t(checked) * count > kBruteForceTests && std::isfinite(inv_cell) && longest < 1e30f) {
    // Many: through a grid of the triangles' boxes
    grid_.build(lo_, hi_, inv_cell, pool_, grid_part_boxes_);
    pool_.parallelFor(checked, kGrainCollide, [&](uint32_t begin, uint32_t end) {
      for (uint32_t k = begin; k < end; ++k) {
        const uint32_t t = checked_[k];
        visitBox(grid_, lo_[t], hi_[t], inv_cell, 0, [&](uint32_t o) { test(t, o); });
      }
    });
  } else {
    // A few: against every triangle
    for (uint32_t t : checked_)
      for (uint32_t o = 0; o < count; ++o) {
        const vec3 lo = lo_[t], hi = hi_[t], elo = lo_[o], ehi = hi_[o];
        if (lo.x <= ehi.x && elo.x <= hi.x && lo.y <= ehi.y && elo.y <= hi.y && lo.z <= ehi.z && elo.z <= hi.z)
          test(t, o);
      }
  }
  for (uint32_t t = 0; t < count; ++t)
    if (crossing_[t]) {
      free_[triangles[t].x] = free_[triangles[t].y] = free_[triangles[t].z] = 1;
      tangles_ = true;
    }
}

void CpuContact::buildLists(const std::vector<glm::vec4>& pos, const std::vector<uvec4>& triangles, uint32_t count,
                            float radius) {
  const float reach = contactReach(radius);
  const uint32_t n = uint32_t(pos.size()), edge_count = uint32_t(edges_.size());
  auto at = [&](uint32_t i) { return vec3(pos[i]); };
  vf_.clear();
  ee_.clear();
  lists_ = false;
  const float inv_cell = listCell(pos, reach);
  if (!(inv_cell > 0.0f)) return;
  const float reach2 = reach * reach;
  // Particles against the triangles that do not hold them: the boxes of the triangles in the grid,
  // each particle's box of half-width `reach` against them
  boxTriangles(pos, triangles, count);
  grid_.build(lo_, hi_, inv_cell, pool_, grid_part_boxes_);
  gatherPairs(pool_, n, kGrainCollide, kSearchShares, vf_, [&](uint32_t v, std::vector<uvec4>& found) {
    const vec3 p = at(v), plo = p - vec3(reach), phi = p + vec3(reach);
    visitBox(grid_, plo, phi, inv_cell, 0, [&](uint32_t t) {
      const uvec4 tri = triangles[t];
      if (v == tri.x || v == tri.y || v == tri.z) return;
      if (pointTriangleDistance2(p, at(tri.x), at(tri.y), at(tri.z)) < reach2)
        found.push_back(uvec4(v, tri.x, tri.y, tri.z));
    });
  });
  // Edges against the edges that share no particle with them, each pair once
  boxEdges(pos);
  grid_.build(lo_, hi_, inv_cell, pool_, grid_part_boxes_);
  gatherPairs(pool_, edge_count, kGrainCollide, kSearchShares, ee_, [&](uint32_t k, std::vector<uvec4>& found) {
    const uvec2 e = edges_[k];
    const vec3 elo = lo_[k] - vec3(reach), ehi = hi_[k] + vec3(reach);
    visitBox(grid_, elo, ehi, inv_cell, k + 1, [&](uint32_t j) {
      const uvec2 f = edges_[j];
      if (f.x == e.x || f.x == e.y || f.y == e.x || f.y == e.y) return;
      if (segmentDistance2(at(e.x), at(e.y), at(f.x), at(f.y)) < reach2) found.push_back(uvec4(e, f));
    });
  });
  // The same lists whatever the threads' order (visitBox meets each pair once)
  std::sort(vf_.begin(), vf_.end(), less4);
  std::sort(ee_.begin(), ee_.end(), less4);
  base_ = pos;
  built_pairs_ = vf_.size() + ee_.size();
  turn_ = glm::dquat(1.0, 0.0, 0.0, 0.0);
  list_radius_ = radius;
  lists_ = true;
  ++builds_;
}

void CpuContact::boxTriangles(const std::vector<glm::vec4>& pos, const std::vector<uvec4>& triangles, uint32_t count) {
  lo_.resize(count);
  hi_.resize(count);
  for (uint32_t t = 0; t < count; ++t) {
    const vec3 a = vec3(pos[triangles[t].x]), b = vec3(pos[triangles[t].y]), c = vec3(pos[triangles[t].z]);
    lo_[t] = glm::min(a, glm::min(b, c));
    hi_[t] = glm::max(a, glm::max(b, c));
  }
}

void CpuContact::boxEdges(const std::vector<glm::vec4>& pos) {
  lo_.resize(edges_.size());
  hi_.resize(edges_.size());
  for (size_t k = 0; k < edges_.size(); ++k) {
    const vec3 a = vec3(pos[edges_[k].x]), b = vec3(pos[edges_[k].y]);
    lo_[k] = glm::min(a, b);
    hi_[k] = glm::max(a, b);
  }
}

float CpuContact::listCell(const std::vector<glm::vec4>& pos, float reach) const {
  // Cells as wide as the reach and the mean edge, and at least an eighth of the longest edge, so
  // that no box spans more than a few cells
  double sum = 0.0;
  float longest = 0.0f;
  for (const uvec2 e : edges_) {
    const float l = std::sqrt(length2(vec3(pos[e.y]) - vec3(pos[e.x])));
    sum += double(l);
    longest = std::max(longest, l);
  }
  const float mean = edges_.empty() ? 0.0f : float(sum / double(edges_.size()));
  const float inv_cell = 1.0f / std::max(reach + mean, (reach + longest) * 0.125f);
  return std::isfinite(inv_cell) && inv_cell > 0.0f && longest < 1e30f ? inv_cell : 0.0f;
}

bool CpuContact::repairLists(const std::vector<glm::vec4>& pos, const std::vector<uvec4>& triangles, uint32_t count,
                             float radius) {
  // Why a repair keeps every pair closer than the radius in the lists. Let d(v) be particle v's
  // travel since its base and say a pair was looked at at time t0 (listed when closer than the
  // reach it was looked for with). At any later time t the lists are used, every particle's d lies
  // within T = contactTravel of one point (the travels' box is small, or a repair looked again at
  // the pairs of every particle beyond T of `middle`), so a pair's particles i, j have
  // |d_i(t) - d_j(t)| < 2T. A pair's distance falls by at most the largest difference of its
  // particles' displacements since t0, |(d_i(t) - d_i(t0)) - (d_j(t) - d_j(t0))|. A pair of the
  // whole build (t0: every d zero) has fallen by less than 2T < SKIN x radius since, so one not
  // listed then is still beyond the radius. A pair of a repair holds a particle beyond T at t0,
  // whose base the repair moves so that its d is `middle`: then |d_i(t0) - d_j(t0)| < 2T too, the
  // pair falls by less than 4T, and the repair looks as far as contactRepairReach. A pair both
  // keep stays until one of its particles goes beyond T, when a repair drops it and looks again.
  const uint32_t n = uint32_t(pos.size()), edge_count = uint32_t(edges_.size());
  const float travel = contactTravel(radius), reach = contactRepairReach(radius), reach2 = reach * reach;
  // Each particle's travel: since its base, or in the frame of the sheet's turn (turnedTravel)
  if (travel_.size() != n) {
    travel_.resize(n);
    for (uint32_t i = 0; i < n; ++i) travel_[i] = vec3(pos[i]) - vec3(base_[i]);
  }
  // The travel most particles share: the componentwise median
  vec3 middle;
  for (int c = 0; c < 3; ++c) {
    travels_.resize(n);
    for (uint32_t i = 0; i < n; ++i) travels_[i] = travel_[i][c];
    std::nth_element(travels_.begin(), travels_.begin() + n / 2, travels_.end());
    middle[c] = travels_[n / 2];
  }
  if (!(length2(middle) < 1e30f)) return false;
  moved_.assign(n, 0);
  dirty_.clear();
  for (uint32_t i = 0; i < n; ++i)
    if (!(length2(travel_[i] - middle) < travel * travel)) {
      moved_[i] = 1;
      dirty_.push_back(i);
    }
  if (dirty_.empty() || dirty_.size() > n / kRepairShare) return false;
  const float inv_cell = listCell(pos, reach);
  if (!(inv_cell > 0.0f)) return false;
  auto at = [&](uint32_t i) { return vec3(pos[i]); };
  auto touched = [&](uvec4 q) { return (moved_[q.x] | moved_[q.y] | moved_[q.z] | moved_[q.w]) != 0; };
  vf_.erase(std::remove_if(vf_.begin(), vf_.end(), touched), vf_.end());
  ee_.erase(std::remove_if(ee_.begin(), ee_.end(), touched), ee_.end());
  std::vector<uvec4> added_vf, added_ee;
  // Calls look(k, found) for each of `dirty_` in parallel and gathers what they find into `added`
  auto search = [&](std::vector<uvec4>& added, auto&& look) {
    gatherPairs(pool_, uint32_t(dirty_.size()), kGrainRepair, 1, added,
                [&](uint32_t k, std::vector<uvec4>& found) { look(dirty_[k], found); });
  };
  // The particles that moved against every triangle near them
  boxTriangles(pos, triangles, count);
  grid_.build(lo_, hi_, inv_cell, pool_, grid_part_boxes_);
  search(added_vf, [&](uint32_t v, std::vector<uvec4>& found) {
    const vec3 p = at(v);
    visitBox(grid_, p - vec3(reach), p + vec3(reach), inv_cell, 0, [&](uint32_t t) {
      const uvec4 tri = triangles[t];
      if (v == tri.x || v == tri.y || v == tri.z) return;
      if (pointTriangleDistance2(p, at(tri.x), at(tri.y), at(tri.z)) < reach2)
        found.push_back(uvec4(v, tri.x, tri.y, tri.z));
    });
  });
  // The triangles with a particle that moved against every other particle near them (those that
  // moved found theirs above)
  points_.resize(n);
  for (uint32_t i = 0; i < n; ++i) points_[i] = at(i);
  points_grid_.build(points_, points_, inv_cell, pool_, grid_part_boxes_);
  dirty_.clear();
  for (uint32_t t = 0; t < count; ++t)
    if (moved_[triangles[t].x] | moved_[triangles[t].y] | moved_[triangles[t].z]) dirty_.push_back(t);
  search(added_vf, [&](uint32_t t, std::vector<uvec4>& found) {
    const uvec4 tri = triangles[t];
    const vec3 a = at(tri.x), b = at(tri.y), c = at(tri.z);
    visitBox(points_grid_, lo_[t] - vec3(reach), hi_[t] + vec3(reach), inv_cell, 0, [&](uint32_t v) {
      if (moved_[v] || v == tri.x || v == tri.y || v == tri.z) return;
      if (pointTriangleDistance2(at(v), a, b, c) < reach2) found.push_back(uvec4(v, tri.x, tri.y, tri.z));
    });
  });
  // The edges with a particle that moved against every edge near them, a pair of two such from the
  // first of them
  boxEdges(pos);
  grid_.build(lo_, hi_, inv_cell, pool_, grid_part_boxes_);
  dirty_.clear();
  for (uint32_t k = 0; k < edge_count; ++k)
    if (moved_[edges_[k].x] | moved_[edges_[k].y]) dirty_.push_back(k);
  search(added_ee, [&](uint32_t k, std::vector<uvec4>& found) {
    const uvec2 e = edges_[k];
    visitBox(grid_, lo_[k] - vec3(reach), hi_[k] + vec3(reach), inv_cell, 0, [&](uint32_t j) {
      const uvec2 f = edges_[j];
      if (j == k || f.x == e.x || f.x == e.y || f.y == e.x || f.y == e.y) return;
      if ((moved_[f.x] | moved_[f.y]) && j < k) return;
      if (segmentDistance2(at(e.x), at(e.y), at(f.x), at(f.y)) < reach2)
        found.push_back(j < k ? uvec4(f, e) : uvec4(e, f));
    });
  });
  // The same lists whatever the threads' order
  std::sort(added_vf.begin(), added_vf.end(), less4);
  std::sort(added_ee.begin(), added_ee.end(), less4);
  vf_.insert(vf_.end(), added_vf.begin(), added_vf.end());
  ee_.insert(ee_.end(), added_ee.begin(), added_ee.end());
  // A moved particle's base goes where its travel is `middle`: by as much as its travel is not
  for (uint32_t i = 0; i < n; ++i)
    if (moved_[i]) base_[i] = glm::vec4(vec3(base_[i]) + (travel_[i] - middle), pos[i].w);
  ++repairs_done_;
  return true;
}

void CpuContact::clusterBases(float radius) {
  using glm::ivec3;
  const uint32_t n = uint32_t(base_.size());
  cluster_count_ = 0;
  cluster_pairs_.clear();
  // The longest edge between bases (a repair moves a base off where the particle was)
  float longest2 = 0.0f;
  for (const uvec2 e : edges_) longest2 = std::max(longest2, length2(vec3(base_[e.y]) - vec3(base_[e.x])));
  const float longest = std::sqrt(longest2), width = kClusterWidth * (contactReach(radius) + longest);
  cluster_far_ = width - 2.0f * longest - radius;
  const float inv = 1.0f / width;
  if (n == 0 || !(cluster_far_ > 0.0f) || !std::isfinite(inv) || !(longest < 1e30f)) return;
  // The particles in the order of their cells, a cluster's together
  std::vector<std::pair<ivec3, uint32_t>> cells(n);
  auto less3 = [](ivec3 a, ivec3 b) { return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z; };
  for (uint32_t i = 0; i < n; ++i) cells[i] = {cellOf(vec3(base_[i]), inv), i};
  std::sort(cells.begin(), cells.end(), [&](const auto& a, const auto& b) {
    return less3(a.first, b.first) || (a.first == b.first && a.second < b.second);
  });
  std::vector<ivec3> keys;
  cluster_members_.resize(n);
  cluster_start_.clear();
  for (uint32_t k = 0; k < n; ++k) {
    if (keys.empty() || keys.back() != cells[k].first) {
      keys.push_back(cells[k].first);
      cluster_start_.push_back(k);
    }
    cluster_members_[k] = cells[k].second;
  }
  cluster_start_.push_back(n);
  cluster_count_ = uint32_t(keys.size());
  // Each cluster with itself and with those in the 26 cells around it, each pair once
  for (uint32_t a = 0; a < cluster_count_; ++a)
    for (int z = -1; z <= 1; ++z)
      for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x) {
          const ivec3 other = keys[a] + ivec3(x, y, z);
          if (less3(other, keys[a])) continue;
          const auto it = std::lower_bound(keys.begin(), keys.end(), other, less3);
          if (it != keys.end() && *it == other) cluster_pairs_.push_back(uvec2(a, uint32_t(it - keys.begin())));
        }
}

bool CpuContact::clustersHold(vec3 lo, vec3 hi, float radius) {
  // Why the lists still hold every pair closer than the radius (the proof of repairLists, in the
  // turned frame of turnedTravel). A pair the lists lack was apart by at least the reach at its
  // particles' bases (or a repair's reach less two travels), and its distance has fallen by at
  // most the largest |q_k - q_l| of its particles k, l. Where every such k and l lie in clusters A
  // and B next to each other (or one), |q_k - q_l| <= T_A + T_B + |m_A - m_B| (m the middle of a
  // cluster's travels' box, T its half-diagonal), which must stay within two travels, as the
  // whole sheet's spread must without clusters. Where some k and l lie in clusters apart, their
  // bases are a cluster's width apart along an axis, the pair's at least that less two longest
  // edges, and it has fallen by at most the whole spread: cluster_far_ less the radius allows.
  if (cluster_key_ != builds_ + repairs_done_) {
    clusterBases(radius);
    cluster_key_ = builds_ + repairs_done_;
  }
  if (cluster_count_ == 0 || !(glm::length(hi - lo) < cluster_far_)) return false;
  cluster_box_.resize(cluster_count_);
  pool_.parallelFor(cluster_count_, kGrainRepair, [&](uint32_t begin, uint32_t end) {
    for (uint32_t a = begin; a < end; ++a) {
      vec3 blo(INFINITY), bhi(-INFINITY);
      for (uint32_t k = cluster_start_[a]; k < cluster_start_[a + 1]; ++k) {
        blo = glm::min(blo, travel_[cluster_members_[k]]);
        bhi = glm::max(bhi, travel_[cluster_members_[k]]);
      }
      cluster_box_[a] = glm::vec4(0.5f * (blo + bhi), 0.5f * glm::length(bhi - blo));
    }
  });
  const float budget = 2.0f * contactTravel(radius);
  for (const uvec2 p : cluster_pairs_) {
    const glm::vec4 a = cluster_box_[p.x], b = cluster_box_[p.y];
    if (!(a.w + b.w + glm::length(vec3(a) - vec3(b)) < budget)) return false;
  }
  return true;
}

std::pair<vec3, vec3> CpuContact::turnedTravel(const std::vector<glm::vec4>& pos) {
  // Why a turn keeps the lists' proof (repairLists): for any rotation R and points c, c', the
  // distance between particles i and j is |R^T (x_i - x_j)| = |(b_i - b_j) + (q_i - q_j)| with
  // q_i = R^T (x_i - c) - (b_i - c') their travel in the turned frame, so a pair's distance
  // differs from its bases' by at most |q_i - q_j|, as it does by |d_i - d_j| with no turn. R may
  // be any rotation at any call: the best fit only makes the travels small.
  using glm::dmat3;
  using glm::dvec3;
  const uint32_t n = uint32_t(pos.size());
  travel_.resize(n);
  if (n == 0) return {vec3(0.0f), vec3(0.0f)};
  // The centroids and the cross-covariance of the positions and the bases, about the first
  // particle's (small sums), in chunks added in their order
  auto d3 = [](glm::vec4 v) { return dvec3(v.x, v.y, v.z); };
  const dvec3 x0 = d3(pos[0]), b0 = d3(base_[0]);
  struct Moments {
    dvec3 x{0.0}, b{0.0};
    dmat3 xb{0.0};
  };
  const uint32_t chunks = pool_.chunksFor(n, kGrainParticles);
  std::vector<Moments> parts(chunks);
  pool_.run(chunks, [&](uint32_t c) {
    Moments m;
    for (uint32_t i = WorkerPool::chunkBound(n, chunks, c); i < WorkerPool::chunkBound(n, chunks, c + 1); ++i) {
      const dvec3 x = d3(pos[i]) - x0, b = d3(base_[i]) - b0;
      m.x += x;
      m.b += b;
      m.xb += glm::outerProduct(x, b);
    }
    parts[c] = m;
  });
  Moments all;
  for (const Moments& m : parts) {
    all.x += m.x;
    all.b += m.b;
    all.xb += m.xb;
  }
  const dvec3 cx = all.x / double(n), cb = all.b / double(n);
  const dmat3 a = all.xb - double(n) * glm::outerProduct(cx, cb);
  // The rotation of A's polar decomposition, the turn that carries the bases' shape nearest onto
  // the positions' (Müller et al., "A Robust Method to Extract the Rotational Part of
  // Deformations", 2016: a flat sheet's rank-2 A is no trouble), from the last call's
  for (int k = 0; k < 32; ++k) {
    const dmat3 r = glm::mat3_cast(turn_);
    const dvec3 omega = glm::cross(r[0], a[0]) + glm::cross(r[1], a[1]) + glm::cross(r[2], a[2]);
    const double w =
        glm::length(omega) / (std::abs(glm::dot(r[0], a[0]) + glm::dot(r[1], a[1]) + glm::dot(r[2], a[2])) + 1e-30);
    if (!(w > 1e-12) || !std::isfinite(w)) break;
    turn_ = glm::normalize(glm::angleAxis(w, glm::normalize(omega)) * turn_);
  }
  if (!std::isfinite(turn_.w + turn_.x + turn_.y + turn_.z)) turn_ = glm::dquat(1.0, 0.0, 0.0, 0.0);
  const dmat3 rt = glm::transpose(glm::mat3_cast(turn_));
  struct Box {
    glm::uvec3 lo{~0u}, hi{0u};
  };
  std::vector<Box> boxes(chunks);
  pool_.run(chunks, [&](uint32_t c) {
    Box box;
    for (uint32_t i = WorkerPool::chunkBound(n, chunks, c); i < WorkerPool::chunkBound(n, chunks, c + 1); ++i) {
      const vec3 q = vec3(rt * (d3(pos[i]) - x0 - cx) - (d3(base_[i]) - b0 - cb));
      travel_[i] = q;
      for (int k = 0; k < 3; ++k) {
        box.lo[k] = std::min(box.lo[k], orderedBits(q[k]));
        box.hi[k] = std::max(box.hi[k], orderedBits(q[k]));
      }
    }
    boxes[c] = box;
  });
  Box box;
  for (const Box& b : boxes) {
    box.lo = glm::min(box.lo, b.lo);
    box.hi = glm::max(box.hi, b.hi);
  }
  return {orderedCorner(box.lo), orderedCorner(box.hi)};
}

uint64_t CpuContact::memoryBytes() const {
  return capacityBytes(half_start_) + capacityBytes(half_) + capacityBytes(half_slack_) + capacityBytes(half_fill_) +
         capacityBytes(edges_) + capacityBytes(free_) + capacityBytes(was_free_) + capacityBytes(checked_) +
         capacityBytes(sums_) + capacityBytes(crossing_) + capacityBytes(vf_) + capacityBytes(ee_) +
         capacityBytes(base_) + capacityBytes(lo_) + capacityBytes(hi_) + capacityBytes(nearest2_) +
         capacityBytes(grid_.start) + capacityBytes(grid_.entry) + capacityBytes(grid_.fill) +
         capacityBytes(grid_.last) + capacityBytes(points_) + capacityBytes(moved_) + capacityBytes(dirty_) +
         capacityBytes(travels_) + capacityBytes(travel_) + capacityBytes(cluster_members_) +
         capacityBytes(cluster_start_) + capacityBytes(cluster_pairs_) + capacityBytes(cluster_box_) +
         capacityBytes(points_grid_.start) + capacityBytes(points_grid_.entry) + capacityBytes(points_grid_.fill) +
         capacityBytes(points_grid_.last);
}

} // namespace tender
