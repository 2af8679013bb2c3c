#include "cpu_contact.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <mutex>

#include <glm/gtc/quaternion.hpp>
#include <glm/gtx/component_wise.hpp>

#include "cpu_collision.h"
#include "cpu_contact_search.h"
#include "worker_pool.h"

namespace tender {

using namespace shaderio;
using namespace contact_search;
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

} // namespace

void CpuContact::computeBounds(const std::vector<glm::vec4>& pos, const std::vector<glm::vec4>& prev,
                               const std::vector<uvec4>& triangles, uint32_t count, const SimUniforms& u, uint32_t s,
                               std::vector<float>& bound, std::vector<glm::vec4>& push) {
  const uint32_t n = uint32_t(pos.size());
  const float radius = u.contact.radius, thickness = u.contact.thickness, scale = u.contact.fixed_units;
  bound.resize(n);
  push.resize(n);
  const auto [travel_lo, travel_hi] = gatherFrame(pos, prev, u, s);
  if (edges_key_ != count) listEdges(triangles, count);
  keepLists(pos, triangles, count, radius, travel_lo, travel_hi);
  sums_.assign(n, glm::ivec4(0));
  findCrossings(pos, triangles, count, s == 0 && (u.contact_check.mode & SIM_CONTACT_CHECK_ALL) != 0u, thickness,
                scale);
  lowerNearest(pos, radius, thickness, scale, u.contact.fraction);
  const uint32_t none = std::bit_cast<uint32_t>(radius * radius);
  uint64_t contacts = 0;
  for (uint32_t i = 0; i < n; ++i) {
    contacts += nearest2_[i] < none ? 1u : 0u;
    bound[i] = free_[i] ? INFINITY : slideBound(std::bit_cast<float>(nearest2_[i]), radius, u.contact.fraction);
    push[i] =
        glm::vec4(contactPushWithin(contactAverage(sums_[i], scale), std::bit_cast<float>(nearest2_[i]), radius), 0.0f);
  }
  contacts_ = contacts;
}

std::pair<vec3, vec3> CpuContact::gatherFrame(const std::vector<glm::vec4>& pos, const std::vector<glm::vec4>& prev,
                                              const SimUniforms& u, uint32_t s) {
  const uint32_t n = uint32_t(pos.size());
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
  return {orderedCorner(all.travel_lo), orderedCorner(all.travel_hi)};
}

void CpuContact::listEdges(const std::vector<uvec4>& triangles, uint32_t count) {
  edges_.clear();
  for (uint32_t t = 0; t < count; ++t) {
    const uvec4 tri = triangles[t];
    for (uvec2 e : {uvec2(tri.x, tri.y), uvec2(tri.y, tri.z), uvec2(tri.z, tri.x)})
      edges_.push_back(uvec2(std::min(e.x, e.y), std::max(e.x, e.y)));
  }
  std::sort(edges_.begin(), edges_.end(), [](uvec2 a, uvec2 b) { return a.x != b.x ? a.x < b.x : a.y < b.y; });
  edges_.erase(std::unique(edges_.begin(), edges_.end()), edges_.end());
  ownTriangles(triangles, count);
  tree_.clear();
  edges_key_ = count;
  lists_ = false;
}

void CpuContact::keepLists(const std::vector<glm::vec4>& pos, const std::vector<uvec4>& triangles, uint32_t count,
                           float radius, vec3 travel_lo, vec3 travel_hi) {
  const uint32_t n = uint32_t(pos.size());
  // The pair lists hold every pair that can be closer than r while the particles' travel since
  // they were built stays within contactTravel of one point (listsOutgrown)
  const bool usable = lists_kept_ != Lists::Rebuilt && lists_ && list_radius_ == radius && base_.size() == n;
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
  const bool repairable = usable && finite && vf_.size() + ee_.size() <= 2 * built_pairs_ + n / kRepairShare;
  if (!fresh && !(repairable && repairLists(pos, triangles, count, radius))) buildLists(pos, triangles, count, radius);
}

void CpuContact::lowerNearest(const std::vector<glm::vec4>& pos, float radius, float thickness, float scale,
                              float fraction) {
  const float r2 = radius * radius;
  const uint32_t none = std::bit_cast<uint32_t>(r2);
  nearest2_.assign(pos.size(), lists_ ? none : 0u); // positions gone wrong (no lists): nothing moves
  weighed_.resize(vf_.size() + ee_.size());
  near_.assign(vf_.size() + ee_.size(), 0);
  auto at = [&](uint32_t i) { return vec3(pos[i]); };
  // Each pair closer than r lowers the bounds of its four particles and sets them their
  // half-spaces (slideConstraint, kept for the substep's slide and settle); one closer than the
  // thickness pushes them apart (contactPush), summed in fixed point. Pairs with a free particle
  // are left out: the sheet untangles there as the repulsion alone lets it. Neither the minimum
  // nor the integer sums depend on the order of the pairs, so nothing depends on the thread count.
  for (const bool edge : {false, true}) {
    const std::vector<uvec4>& list = edge ? ee_ : vf_;
    const size_t first = edge ? vf_.size() : 0;
    pool_.parallelFor(uint32_t(list.size()), kGrainConstraints, [&](uint32_t begin, uint32_t end) {
      for (uint32_t k = begin; k < end; ++k) {
        const uvec4 q = list[k];
        if (free_[q.x] | free_[q.y] | free_[q.z] | free_[q.w]) continue;
        const vec3 x0 = at(q.x), x1 = at(q.y), x2 = at(q.z), x3 = at(q.w);
        const NearestPoints c = edge ? segmentSegment(x0, x1, x2, x3) : pointTriangle(x0, x1, x2, x3);
        if (!(c.d2 < r2)) continue;
        for (uint32_t i : {q.x, q.y, q.z, q.w}) lower(nearest2_[i], c.d2);
        Weighed& w = weighed_[first + k];
        w.c = c;
        for (uint32_t j = 0; j < 4; ++j) w.h[j] = slideConstraint(x0, x1, x2, x3, c, edge, radius, fraction, j);
        near_[first + k] = 1;
        if (!(c.d2 < thickness * thickness)) continue;
        const glm::vec4 x[4] = {pos[q.x], pos[q.y], pos[q.z], pos[q.w]};
        for (uint32_t j = 0; j < 4; ++j)
          addFixed(sums_, q[j], contactPush(x[0], x[1], x[2], x[3], c, thickness, j), scale);
      }
    });
  }
}

// Each pair's half-spaces, as computeBounds weighed them (lowerNearest); `visit` sees each of its
// particles' (a pair once, from any thread: what it sums and lowers must not depend on the order)
// with the pair, its nearest points and the particle's place in it
template <class Visit>
void CpuContact::visitHalfSpaces(Visit&& visit) {
  for (const bool edge : {false, true}) {
    const std::vector<uvec4>& list = edge ? ee_ : vf_;
    const size_t first = edge ? vf_.size() : 0;
    pool_.parallelFor(uint32_t(list.size()), kGrainConstraints, [&](uint32_t begin, uint32_t end) {
      for (uint32_t k = begin; k < end; ++k) {
        if (!near_[first + k]) continue;
        const Weighed& w = weighed_[first + k];
        for (uint32_t j = 0; j < 4; ++j)
          if (w.h[j].h.w >= 0.0f) visit(list[k], w.c, edge, j, w.h[j]);
      }
    });
  }
}

void CpuContact::slide(const std::vector<glm::vec4>& start, const std::vector<glm::vec4>& pos, const SimUniforms& u,
                       std::vector<glm::vec4>& passed, std::vector<glm::vec4>& excess, std::vector<float>& share) {
  const uint32_t n = uint32_t(pos.size());
  const float scale = u.contact.fixed_units;
  passed.assign(n, glm::vec4(0.0f));
  excess.assign(n, glm::vec4(0.0f));
  share.assign(n, 1.0f);
  if (!lists_) return; // positions gone wrong: the bounds hold every particle
  auto pairs = [&](auto&& visit) { visitHalfSpaces(visit); };
  // What each step's excess passes on to the other primitive of its pairs
  sums_.assign(n, glm::ivec4(0));
  pairs([&](const uvec4& q, const NearestPoints& c, bool edge, uint32_t j, const SlideHalf& h) {
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
  pairs([&](const uvec4& q, const NearestPoints&, bool, uint32_t j, const SlideHalf& h) {
    const vec3 e = slideExcess(h, step(q[j]));
    if (e != vec3(0.0f)) addFixed(sums_, q[j], e, scale);
  });
  for (uint32_t i = 0; i < n; ++i) excess[i] = glm::vec4(contactAverage(sums_[i], scale), 0.0f);
  std::vector<uint32_t>& bits = share_bits_;
  bits.assign(n, std::bit_cast<uint32_t>(1.0f));
  pairs([&](const uvec4& q, const NearestPoints&, bool, uint32_t j, const SlideHalf& h) {
    const float s = slideShare(h, step(q[j]) + vec3(excess[q[j]]));
    if (s < 1.0f) lower(bits[q[j]], s);
  });
  for (uint32_t i = 0; i < n; ++i) share[i] = std::bit_cast<float>(bits[i]);
}

void CpuContact::listHalfSpaces(uint32_t n) {
  // Counted, scanned, filled (a particle's in any order: room() takes their minimum)
  half_start_.assign(n + 1, 0u);
  if (!lists_) return;
  visitHalfSpaces([&](const uvec4& q, const NearestPoints&, bool, uint32_t j, const SlideHalf&) {
    std::atomic_ref<uint32_t>(half_start_[q[j] + 1]).fetch_add(1u, std::memory_order_relaxed);
  });
  for (uint32_t i = 0; i < n; ++i) half_start_[i + 1] += half_start_[i];
  half_.resize(half_start_[n]);
  half_slack_.resize(half_start_[n]);
  half_fill_.assign(half_start_.begin(), half_start_.end() - 1);
  visitHalfSpaces([&](const uvec4& q, const NearestPoints&, bool, uint32_t j, const SlideHalf& h) {
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
  if (uint64_t(checked) * count > kBruteForceTests && longest < 1e30f) {
    // Many: through a tree of the triangles' boxes (finite ones: its groups compare their centres)
    tree_.fit(lo_, hi_, pool_);
    pool_.parallelFor(checked, kGrainCollide, [&](uint32_t begin, uint32_t end) {
      for (uint32_t k = begin; k < end; ++k) {
        const uint32_t t = checked_[k];
        tree_.visit(lo_[t], hi_[t], [&](uint32_t o) { test(t, o); });
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

uint64_t CpuContact::memoryBytes() const {
  return capacityBytes(half_start_) + capacityBytes(half_) + capacityBytes(half_slack_) + capacityBytes(half_fill_) +
         capacityBytes(edges_) + capacityBytes(free_) + capacityBytes(was_free_) + capacityBytes(checked_) +
         capacityBytes(sums_) + capacityBytes(crossing_) + capacityBytes(vf_) + capacityBytes(ee_) +
         capacityBytes(base_) + capacityBytes(lo_) + capacityBytes(hi_) + capacityBytes(nearest2_) +
         tree_.memoryBytes() + capacityBytes(moved_) + capacityBytes(dirty_) + capacityBytes(travels_) +
         capacityBytes(travel_) + capacityBytes(cluster_members_) + capacityBytes(cluster_start_) +
         capacityBytes(cluster_pairs_) + capacityBytes(cluster_box_) + capacityBytes(ball_) + capacityBytes(segment_) +
         capacityBytes(own_) + capacityBytes(own_particles_) + capacityBytes(owned_) + capacityBytes(weighed_) +
         capacityBytes(near_);
}

} // namespace tender
