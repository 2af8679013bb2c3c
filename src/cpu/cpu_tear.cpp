// The CPU solver's tear stage: the constraints stretched past their tear length marked (the
// shaders' markTear, with the SIMD length test), what no longer stands on a live triangle let go
// (markUnsupported), and the colours and triangles compacted, in their order (the GPU scans).
#include <algorithm>

#include "cpu_solver.h"
#include "simd_kernels.h"
#include "worker_pool.h"

namespace tender {

using namespace shaderio;

// Marks the live constraints among array slots [begin, end) of the split arrays that the shaders'
// markTear tears (counted in counters_.torn_new). The SIMD length test picks out the few that can
// tear, 64 at most at a time.
void CpuSolver::markTearsRange(SheetElements& e, uint32_t begin, uint32_t end) {
  const SimUniforms& u = e.u;
  const vec4* p = pos_.data();
  const uint32_t *ca = con_a_.data(), *cb = con_b_.data(), *kind = con_kind_.data(), *id = con_id_.data();
  const float* rest = con_rest_.data();
  auto check = [&](uint32_t k) {
    e.markTear(Constraint{ca[k], cb[k], rest[k], (id[k] << SIM_KIND_BITS) | kind[k]}, p[ca[k]], p[cb[k]]);
  };
  for (const ColorRange& range : colors_) {
    const uint32_t first = std::max(begin, range.first), last = std::min(end, range.first + range.count);
    if (first >= last) continue;
    uint32_t k = first;
    if (simd_)
      for (uint32_t n; (n = std::min(64u, (last - k) & ~3u)) > 0; k += n)
        for (uint64_t over = simd::stretched(&p[0].x, ca, cb, rest, u.tear_factor, k, n); over; over &= over - 1u)
          check(k + uint32_t(__builtin_ctzll(over)));
    for (; k < last; ++k) check(k);
  }
}

uint32_t CpuSolver::markTears(const SimUniforms& u) {
  counters_.torn_new = 0; // a new substep: nothing torn in it yet
  if (!tearingOn(u.tear_factor)) return 0;
  SheetElements e = elements(u);
  pool_->parallelFor(uint32_t(constraints_.size()), grain_(kGrainConstraints),
                     [&](uint32_t begin, uint32_t end) { markTearsRange(e, begin, end); });
  return counters_.torn_new;
}

uint32_t CpuSolver::markUnsupported(const SimUniforms& u) {
  const uint32_t before = counters_.torn_new;
  SheetElements e = elements(u);
  pool_->parallelFor(uint32_t(constraints_.size()), grain_(kGrainConstraints), [&](uint32_t begin, uint32_t end) {
    for (const ColorRange& range : colors_)
      for (uint32_t k = std::max(begin, range.first); k < std::min(end, range.first + range.count); ++k)
        e.markUnsupported(constraints_[k]);
  });
  return counters_.torn_new - before;
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
        con_hinge_[v] = con_hinge_[k];
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

} // namespace tender
