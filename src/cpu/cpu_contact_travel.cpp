// How far the CPU contact's particles travelled since its pair lists were built (cpu_contact.h):
// with the sheet's turn taken out (turnedTravel), and whether clusters of the sheet next to each
// other travelled alike (clusterBases, clustersHold), so that the lists stand.
#include <algorithm>
#include <cmath>

#include <glm/gtc/quaternion.hpp>
#include <glm/gtx/component_wise.hpp>

#include "cpu_contact.h"
#include "cpu_contact_search.h"
#include "grain.h"
#include "worker_pool.h"

namespace tender {

using namespace shaderio;
using namespace contact_search;
using glm::uvec2;
using glm::vec3;

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

} // namespace tender
