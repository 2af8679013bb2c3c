// The CPU contact's pair lists (cpu_contact.h): the grid of boxes they are searched in, their
// build, and how they are kept while the particles travel: with the sheet's turn taken out
// (turnedTravel), while clusters next to each other travel alike (clustersHold), and repaired
// around the few particles that travelled too far (repairLists).
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
using glm::ivec3;
using glm::uvec2;
using glm::uvec4;
using glm::vec3;

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
  const std::optional<vec3> middle = markMoved(pos, radius);
  if (!middle) return false;
  const float reach = contactRepairReach(radius), inv_cell = listCell(pos, reach);
  if (!(inv_cell > 0.0f)) return false;
  auto touched = [&](uvec4 q) { return (moved_[q.x] | moved_[q.y] | moved_[q.z] | moved_[q.w]) != 0; };
  vf_.erase(std::remove_if(vf_.begin(), vf_.end(), touched), vf_.end());
  ee_.erase(std::remove_if(ee_.begin(), ee_.end(), touched), ee_.end());
  std::vector<uvec4> added_vf, added_ee;
  searchMoved(pos, triangles, count, reach, inv_cell, added_vf, added_ee);
  // The same lists whatever the threads' order
  std::sort(added_vf.begin(), added_vf.end(), less4);
  std::sort(added_ee.begin(), added_ee.end(), less4);
  vf_.insert(vf_.end(), added_vf.begin(), added_vf.end());
  ee_.insert(ee_.end(), added_ee.begin(), added_ee.end());
  // A moved particle's base goes where its travel is `middle`: by as much as its travel is not
  for (uint32_t i = 0; i < uint32_t(pos.size()); ++i)
    if (moved_[i]) base_[i] = glm::vec4(vec3(base_[i]) + (travel_[i] - *middle), pos[i].w);
  ++repairs_done_;
  return true;
}

std::optional<vec3> CpuContact::markMoved(const std::vector<glm::vec4>& pos, float radius) {
  const uint32_t n = uint32_t(pos.size());
  const float travel = contactTravel(radius);
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
  if (!(length2(middle) < 1e30f)) return std::nullopt;
  moved_.assign(n, 0);
  dirty_.clear();
  for (uint32_t i = 0; i < n; ++i)
    if (!(length2(travel_[i] - middle) < travel * travel)) {
      moved_[i] = 1;
      dirty_.push_back(i);
    }
  if (dirty_.empty() || dirty_.size() > n / kRepairShare) return std::nullopt;
  return middle;
}

void CpuContact::searchMoved(const std::vector<glm::vec4>& pos, const std::vector<uvec4>& triangles, uint32_t count,
                             float reach, float inv_cell, std::vector<uvec4>& added_vf, std::vector<uvec4>& added_ee) {
  const uint32_t n = uint32_t(pos.size()), edge_count = uint32_t(edges_.size());
  const float reach2 = reach * reach;
  auto at = [&](uint32_t i) { return vec3(pos[i]); };
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

} // namespace tender
