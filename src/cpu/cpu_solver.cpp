#include "cpu_solver.h"

#include <algorithm>
#include <limits>

namespace tender {

using namespace shaderio;

void CpuSolver::upload(const SheetTopology& topo) {
  topo_ = &topo;
  const uint32_t n = topo.particleCount();
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
  torn_.assign(topo.constraintCount(), 0u);
  triangles_ = topo.triangles;
  triangle_count_ = topo.triangleCount();
  cell_count_.assign(topo.hash_size, 0u);
  cell_start_.assign(topo.hash_size + 1, 0u);
  cell_particles_.assign(n, 0u);
  particle_cell_.assign(n, 0u);
}

void CpuSolver::integrate(const SimUniforms& u, uint32_t s) {
  const float dt2 = u.dt * u.dt;
  const vec4 wind = u.wind[s], twist = u.wind_twist[s], target = u.grab_target[s], grab_prev = u.grab_prev[s];
  for (uint32_t i = 0, n = uint32_t(pos_.size()); i < n; ++i) {
    VerletState st = integrateParticle(pos_[i], prev_[i], rest_[i], uv_[i].x, i == u.grab_index, target, grab_prev,
                                       u.flags, u.gravity, wind, twist, u.damping, dt2);
    pos_[i] = st.pos;
    prev_[i] = st.prev;
  }
}

void CpuSolver::project(const SimUniforms& u, uint32_t iterations) {
  const float stiffness[4] = {u.stiffness.x, u.stiffness.y, u.stiffness.z, u.stiffness.w};
  vec4* p = pos_.data();
  for (uint32_t it = 0; it < iterations; ++it)
    for (const ColorRange& range : colors_) { // Gauss-Seidel over colours
      const Constraint* c = constraints_.data() + range.first;
      for (uint32_t k = 0; k < range.count; ++k) {
        PairDelta d = solveDistance(p[c[k].a], p[c[k].b], c[k].rest, stiffness[c[k].kind_id & SIM_KIND_MASK]);
        p[c[k].a] += vec4(d.da, 0.0f);
        p[c[k].b] += vec4(d.db, 0.0f);
      }
    }
}

void CpuSolver::buildHash(const SimUniforms& u) {
  const uint32_t n = uint32_t(pos_.size());
  std::fill(cell_count_.begin(), cell_count_.end(), 0u);
  for (uint32_t i = 0; i < n; ++i) { // count
    uint32_t h = hashCell(cellOf(vec3(pos_[i]), u.inv_cell), u.hash_mask);
    particle_cell_[i] = h;
    cell_count_[h]++;
  }
  uint32_t sum = 0; // exclusive scan
  for (size_t h = 0; h < cell_count_.size(); ++h) {
    cell_start_[h] = sum;
    sum += cell_count_[h];
  }
  cell_start_[cell_count_.size()] = sum;
  std::copy(cell_start_.begin(), cell_start_.end() - 1, cell_count_.begin()); // scatter cursors
  for (uint32_t i = 0; i < n; ++i) cell_particles_[cell_count_[particle_cell_[i]]++] = i;
}

void CpuSolver::collide(const SimUniforms& u) {
  const uint32_t n = uint32_t(pos_.size());
  const float r = u.collision_radius, r2 = r * r;
  const uint32_t* adj_off = topo_->adj_offsets.data();
  const uint32_t* adj = topo_->adj_list.data();
  for (uint32_t i = 0; i < n; ++i) {
    const vec3 pi = vec3(pos_[i]);
    const ivec3 ci = cellOf(pi, u.inv_cell);
    vec3 sum(0.0f);
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const ivec3 c = ci + ivec3(dx, dy, dz);
          const uint32_t h = hashCell(c, u.hash_mask);
          for (uint32_t k = cell_start_[h], end = cell_start_[h + 1]; k < end; ++k) {
            const uint32_t j = cell_particles_[k];
            const vec3 pj = vec3(pos_[j]);
            const vec3 d = pi - pj;
            if (j == i || dot(d, d) >= r2) continue;
            // Count j once, from its own cell, and never repel connected particles.
            if (cellOf(pj, u.inv_cell) != c) continue;
            if (std::binary_search(adj + adj_off[i], adj + adj_off[i + 1], j)) continue;
            sum += repulsion(pi, pj, r, u.collision_stiffness);
          }
        }
    delta_[i] = vec4(sum, 0.0f);
  }
}

void CpuSolver::floorPass(const SimUniforms& u) {
  const bool collide = (u.flags & SIM_FLAG_COLLISION) != 0u;
  for (size_t i = 0; i < pos_.size(); ++i) {
    vec4 p = pos_[i];
    if (collide && p.w > 0.0f) p += vec4(vec3(delta_[i]), 0.0f);
    VerletState st = floorContact(p, prev_[i], u.floor_y, u.restitution, u.friction);
    pos_[i] = st.pos;
    prev_[i] = st.prev;
  }
}

uint32_t CpuSolver::markTears(const SimUniforms& u) {
  if (u.tear_factor <= 0.0f) return 0;
  uint32_t torn = 0;
  for (const ColorRange& range : colors_)
    for (uint32_t k = range.first; k < range.first + range.count; ++k) {
      const Constraint& c = constraints_[k];
      if (shouldTear(pos_[c.a], pos_[c.b], c.rest, c.kind_id & SIM_KIND_MASK, u.tear_factor, u.tear_kinds)) {
        torn_[c.kind_id >> SIM_KIND_BITS] = 1u;
        ++torn;
      }
    }
  return torn;
}

void CpuSolver::compact() {
  for (ColorRange& range : colors_) {
    uint32_t w = range.first;
    for (uint32_t k = range.first; k < range.first + range.count; ++k)
      if (!torn_[constraints_[k].kind_id >> SIM_KIND_BITS]) constraints_[w++] = constraints_[k];
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
  for (size_t i = 0; i < pos_.size(); ++i) {
    const float w = inverseMass(rest_[i], false, u.flags);
    pos_[i] = vec4(mix(vec3(reset_from_[i]), vec3(rest_[i]), u.reset_alpha), w);
    prev_[i] = pos_[i];
  }
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
    if (collision) {
      buildHash(u);
      collide(u);
    }
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
  PickResult best{SIM_NONE, 0.0f};
  float best_d2 = radius * radius;
  for (uint32_t i = 0; i < pos_.size(); ++i) {
    vec2 r = rayPointDistance2(o, d, vec3(pos_[i]));
    if (r.x <= best_d2 && (best.index == SIM_NONE || r.x < best_d2)) {
      best = {i, r.y};
      best_d2 = r.x;
    }
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

} // namespace tender
