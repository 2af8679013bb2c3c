// The CPU contact's pair lists (cpu_contact.h): the grid of boxes they are searched in, their
// build, and their repair around the few particles that travelled too far (repairLists); how far
// the particles travelled is cpu_contact_travel.cpp's.
#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>

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

// What triangles t and o own (ownTriangles) within `reach` of each other, the pairs `keep` takes:
// their edges' pairs into ee (the lower edge first, as segmentDistance2 weighs them), each one's
// particles against the other triangle into vf. Balls around the triangles and two separating axes
// of two segments part most neighbours of the sheet before their exact distance.
template <class Keep>
void CpuContact::pairsOfTriangles(uint32_t t, uint32_t o, const std::vector<glm::vec4>& pos,
                                  const std::vector<uvec4>& triangles, float reach, Keep&& keep, std::vector<uvec4>& vf,
                                  std::vector<uvec4>& ee) const {
  if (ballsApart(ball_[t], ball_[o], reach)) return;
  const float reach2 = reach * reach;
  auto at = [&](uint32_t i) { return vec3(pos[i]); };
  const uvec4 mine = own_[t], theirs = own_[o];
  for (uint32_t i = 0; i < (mine.w & 3u); ++i)
    for (uint32_t j = 0; j < (theirs.w & 3u); ++j) {
      const uint32_t k = mine[int(i)], l = theirs[int(j)];
      const uvec2 e = edges_[std::min(k, l)], f = edges_[std::max(k, l)];
      if (f.x == e.x || f.x == e.y || f.y == e.x || f.y == e.y || !keep(uvec4(e, f))) continue;
      const Segment& se = segment_[std::min(k, l)];
      const Segment& sf = segment_[std::max(k, l)];
      if (segmentsApart(se.middle, se.side, sf.middle, sf.side, reach)) continue;
      if (segmentDistance2(at(e.x), at(e.y), at(f.x), at(f.y)) < reach2) ee.push_back(uvec4(e, f));
    }
  // A particle farther than the reach from a triangle's ball is farther from the triangle
  auto against = [&](uint32_t owner, uint32_t count, uint32_t other) {
    const uvec4 tri = triangles[other];
    for (uint32_t i = 0; i < count; ++i) {
      const uint32_t v = own_particles_[owner * 3 + i];
      const uvec4 q(v, tri.x, tri.y, tri.z);
      if (v == tri.x || v == tri.y || v == tri.z || !keep(q)) continue;
      if (ballsApart(glm::vec4(at(v), 0.0f), ball_[other], reach)) continue;
      if (pointTriangleDistance2(at(v), at(tri.x), at(tri.y), at(tri.z)) < reach2) vf.push_back(q);
    }
  };
  against(t, mine.w >> 2, o);
  against(o, theirs.w >> 2, t);
}

// Particle v, which no triangle holds, against every triangle within `reach` of it.
void CpuContact::searchLoner(uint32_t v, const std::vector<glm::vec4>& pos, const std::vector<uvec4>& triangles,
                             float reach, std::vector<uvec4>& vf) const {
  const vec3 p = vec3(pos[v]);
  tree_.visit(p - vec3(reach), p + vec3(reach), [&](uint32_t t) {
    const uvec4 tri = triangles[t];
    const vec3 a = vec3(pos[tri.x]), b = vec3(pos[tri.y]), c = vec3(pos[tri.z]);
    if (pointTriangleDistance2(p, a, b, c) < reach * reach) vf.push_back(uvec4(v, tri.x, tri.y, tri.z));
  });
}

void CpuContact::buildLists(const std::vector<glm::vec4>& pos, const std::vector<uvec4>& triangles, uint32_t count,
                            float radius) {
  const float reach = contactReach(radius);
  const uint32_t n = uint32_t(pos.size());
  vf_.clear();
  ee_.clear();
  lists_ = false;
  if (!searchable(pos)) return;
  // One search finds both kinds of pair: the triangles' boxes in a tree, each pair of triangles
  // whose boxes come within the reach met once. Each edge and each particle belongs to the first
  // triangle that holds it (ownTriangles), and two triangles weigh the pairs of what they own: an
  // edge-edge pair within the reach lies in two triangles within it, and a particle within the
  // reach of a triangle lies in one; a pair of triangles is met once, so every pair is. Particles
  // no triangle holds (torn free) look for their triangles on their own.
  boxTriangles(pos, triangles, count);
  tree_.fit(lo_, hi_, pool_);
  const std::vector<BoxTree::Task> tasks = tree_.pairTasks(reach);
  auto all = [](uvec4) { return true; };
  std::mutex merge;
  pool_.parallelFor(
      uint32_t(tasks.size()), 1,
      [&](uint32_t begin, uint32_t end) {
        std::vector<uvec4> vf, ee;
        for (uint32_t k = begin; k < end; ++k)
          tree_.visitPairs(tasks[k], reach,
                           [&](uint32_t t, uint32_t o) { pairsOfTriangles(t, o, pos, triangles, reach, all, vf, ee); });
        const std::lock_guard<std::mutex> lock(merge);
        vf_.insert(vf_.end(), vf.begin(), vf.end());
        ee_.insert(ee_.end(), ee.begin(), ee.end());
      },
      kSearchShares);
  for (uint32_t v = 0; v < n; ++v)
    if (v >= owned_.size() || !owned_[v]) searchLoner(v, pos, triangles, reach, vf_);
  // The same lists whatever the threads' order (the tree meets each pair once)
  std::sort(vf_.begin(), vf_.end(), less4);
  std::sort(ee_.begin(), ee_.end(), less4);
  base_ = pos;
  built_pairs_ = vf_.size() + ee_.size();
  turn_ = glm::dquat(1.0, 0.0, 0.0, 0.0);
  list_radius_ = radius;
  lists_ = true;
  ++builds_;
}

// What each triangle owns for the search of buildLists: the edges (own_[t].xyz, own_[t].w & 3 of
// them) and the particles (own_particles_[3 t ...], own_[t].w >> 2 of them) that no triangle before
// it holds; owned_ marks the particles some triangle holds.
void CpuContact::ownTriangles(const std::vector<uvec4>& triangles, uint32_t count) {
  own_.assign(count, uvec4(0u));
  own_particles_.assign(size_t(count) * 3, 0u);
  std::vector<uint8_t> edge_owned(edges_.size(), 0);
  owned_.clear();
  auto edge_index = [&](uint32_t a, uint32_t b) {
    const uvec2 e(std::min(a, b), std::max(a, b));
    return uint32_t(std::lower_bound(edges_.begin(), edges_.end(), e,
                                     [](uvec2 x, uvec2 y) { return x.x != y.x ? x.x < y.x : x.y < y.y; }) -
                    edges_.begin());
  };
  for (uint32_t t = 0; t < count; ++t) {
    const uvec4 tri = triangles[t];
    uint32_t edges = 0, particles = 0;
    for (const uvec2 e : {uvec2(tri.x, tri.y), uvec2(tri.y, tri.z), uvec2(tri.z, tri.x)}) {
      const uint32_t k = edge_index(e.x, e.y);
      if (edge_owned[k]) continue;
      edge_owned[k] = 1;
      own_[t][int(edges++)] = k;
    }
    for (const uint32_t v : {tri.x, tri.y, tri.z}) {
      if (v >= owned_.size()) owned_.resize(v + 1, 0);
      if (owned_[v]) continue;
      owned_[v] = 1;
      own_particles_[t * 3 + particles++] = v;
    }
    own_[t].w = edges | (particles << 2);
  }
}

void CpuContact::boxTriangles(const std::vector<glm::vec4>& pos, const std::vector<uvec4>& triangles, uint32_t count) {
  lo_.resize(count);
  hi_.resize(count);
  ball_.resize(count);
  for (uint32_t t = 0; t < count; ++t) {
    const vec3 a = vec3(pos[triangles[t].x]), b = vec3(pos[triangles[t].y]), c = vec3(pos[triangles[t].z]);
    lo_[t] = glm::min(a, glm::min(b, c));
    hi_[t] = glm::max(a, glm::max(b, c));
    const vec3 m = (a + b + c) * (1.0f / 3.0f);
    ball_[t] = glm::vec4(m, std::sqrt(std::max({length2(a - m), length2(b - m), length2(c - m)})));
  }
  segment_.resize(edges_.size());
  for (size_t k = 0; k < edges_.size(); ++k) {
    const vec3 a = vec3(pos[edges_[k].x]), b = vec3(pos[edges_[k].y]);
    segment_[k] = {(a + b) * 0.5f, b - a};
  }
}

bool CpuContact::searchable(const std::vector<glm::vec4>& pos) const {
  // Every edge's squared length finite, so that every box is
  for (const uvec2 e : edges_)
    if (!(length2(vec3(pos[e.y]) - vec3(pos[e.x])) <= std::numeric_limits<float>::max())) return false;
  return true;
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
  const float reach = contactRepairReach(radius);
  if (!searchable(pos)) return false;
  auto touched = [&](uvec4 q) { return (moved_[q.x] | moved_[q.y] | moved_[q.z] | moved_[q.w]) != 0; };
  vf_.erase(std::remove_if(vf_.begin(), vf_.end(), touched), vf_.end());
  ee_.erase(std::remove_if(ee_.begin(), ee_.end(), touched), ee_.end());
  std::vector<uvec4> added_vf, added_ee;
  searchMoved(pos, triangles, count, reach, added_vf, added_ee);
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
                             float reach, std::vector<uvec4>& added_vf, std::vector<uvec4>& added_ee) {
  // The pairs with a particle that moved, as buildLists finds them: each triangle that holds one
  // against every triangle near it (two such, from the first of them), what they own (only the
  // pairs with a particle that moved); the moved particles no triangle holds on their own
  auto touched = [&](uvec4 q) { return (moved_[q.x] | moved_[q.y] | moved_[q.z] | moved_[q.w]) != 0; };
  boxTriangles(pos, triangles, count);
  tree_.fit(lo_, hi_, pool_);
  dirty_.clear();
  for (uint32_t t = 0; t < count; ++t)
    if (touched(uvec4(triangles[t].x, triangles[t].y, triangles[t].z, triangles[t].x))) dirty_.push_back(t);
  std::mutex merge;
  pool_.parallelFor(uint32_t(dirty_.size()), kGrainRepair, [&](uint32_t begin, uint32_t end) {
    std::vector<uvec4> vf, ee;
    for (uint32_t k = begin; k < end; ++k) {
      const uint32_t t = dirty_[k];
      tree_.visit(lo_[t] - vec3(reach), hi_[t] + vec3(reach), [&](uint32_t o) {
        const uvec4 other = triangles[o];
        if (o == t || (o < t && touched(uvec4(other.x, other.y, other.z, other.x)))) return;
        pairsOfTriangles(t, o, pos, triangles, reach, touched, vf, ee);
      });
    }
    const std::lock_guard<std::mutex> lock(merge);
    added_vf.insert(added_vf.end(), vf.begin(), vf.end());
    added_ee.insert(added_ee.end(), ee.begin(), ee.end());
  });
  for (uint32_t v = 0; v < uint32_t(pos.size()); ++v)
    if (moved_[v] && (v >= owned_.size() || !owned_[v])) searchLoner(v, pos, triangles, reach, added_vf);
}

} // namespace tender
