// The tree of boxes of the CPU contact's searches (box_tree.h).
#include "box_tree.h"

#include <algorithm>
#include <numeric>

#include "worker_pool.h"

namespace tender {

using glm::vec3;

template <class F>
void BoxTree::eachPart(WorkerPool& pool, F&& f) const {
  const uint32_t parts = uint32_t(parts_.size());
  if (id_.size() >= shared_boxes_)
    pool.run(parts, f);
  else
    for (uint32_t c = 0; c < parts; ++c) f(c);
}

void BoxTree::fit(const std::vector<vec3>& lo, const std::vector<vec3>& hi, WorkerPool& pool) {
  const uint32_t n = uint32_t(lo.size());
  if (n != id_.size() || node_.empty()) return build(lo, hi, pool);
  // The same groups, their boxes anew: each part's leaves' in their order, then each node's from
  // its children's, the deepest first (a subtree's nodes follow its root); then the nodes above
  eachPart(pool, [&](uint32_t c) {
    const Part p = parts_[c];
    for (uint32_t e = p.begin; e < p.end; ++e) {
      lo_[e] = lo[id_[e]];
      hi_[e] = hi[id_[e]];
    }
    for (uint32_t k = p.nodes; k-- > p.node;) fitNode(k);
  });
  for (auto k = above_.rbegin(); k != above_.rend(); ++k) fitNode(*k);
}

void BoxTree::build(const std::vector<vec3>& lo, const std::vector<vec3>& hi, WorkerPool& pool) {
  const uint32_t n = uint32_t(lo.size());
  node_.clear();
  id_.clear();
  if (n == 0) return;
  id_.resize(n);
  std::iota(id_.begin(), id_.end(), 0u);
  centre_.resize(n);
  for (uint32_t i = 0; i < n; ++i) centre_[i] = lo[i] + hi[i];
  const uint32_t nodes = nodeCount(n);
  node_.resize(nodes);
  right_.assign(nodes, 0u);
  lo_.resize(n);
  hi_.resize(n);
  // The first two levels here, then their four subtrees (each a range of nodes and entries that
  // nodeCount fixes) from the pool's threads; the tree is the same whatever the thread count
  parts_.assign(1, Part{0, 0, n, 0});
  above_.clear();
  std::vector<Part> next;
  for (int level = 0; level < 2; ++level) {
    next.clear();
    for (const Part p : parts_) {
      if (p.end - p.begin <= kLeaf) {
        next.push_back(p);
        continue;
      }
      const uint32_t mid = split(p.node, p.begin, p.end);
      above_.push_back(p.node);
      next.push_back({p.node + 1, p.begin, mid, 0});
      next.push_back({right_[p.node], mid, p.end, 0});
    }
    parts_.swap(next);
  }
  for (Part& p : parts_) p.nodes = p.node + nodeCount(p.end - p.begin);
  eachPart(pool, [&](uint32_t c) { buildNode(parts_[c].node, parts_[c].begin, parts_[c].end, lo, hi); });
  // The nodes above them from their children's boxes, the deepest first
  for (auto k = above_.rbegin(); k != above_.rend(); ++k) fitNode(*k);
}

uint32_t BoxTree::split(uint32_t k, uint32_t begin, uint32_t end) {
  // Halves at the median of the centres along the widest side of their box; ties by number, so
  // that the halves are the same sets on every run
  vec3 clo(centre_[id_[begin]]), chi(clo);
  for (uint32_t e = begin; e < end; ++e) {
    clo = glm::min(clo, centre_[id_[e]]);
    chi = glm::max(chi, centre_[id_[e]]);
  }
  const vec3 side = chi - clo;
  const int axis = side.x >= side.y && side.x >= side.z ? 0 : side.y >= side.z ? 1 : 2;
  const uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(id_.begin() + begin, id_.begin() + mid, id_.begin() + end, [&](uint32_t a, uint32_t b) {
    const float ca = centre_[a][axis], cb = centre_[b][axis];
    return ca < cb || (!(cb < ca) && a < b);
  });
  node_[k].begin = begin;
  node_[k].end = end;
  right_[k] = k + 1 + nodeCount(mid - begin);
  return mid;
}

void BoxTree::buildNode(uint32_t k, uint32_t begin, uint32_t end, const std::vector<vec3>& lo,
                        const std::vector<vec3>& hi) {
  if (end - begin <= kLeaf) {
    node_[k].begin = begin;
    node_[k].end = end;
    for (uint32_t e = begin; e < end; ++e) {
      lo_[e] = lo[id_[e]];
      hi_[e] = hi[id_[e]];
    }
    fitNode(k);
    return;
  }
  const uint32_t mid = split(k, begin, end);
  buildNode(k + 1, begin, mid, lo, hi);
  buildNode(right_[k], mid, end, lo, hi);
  fitNode(k);
}

void BoxTree::fitNode(uint32_t k) {
  Node& n = node_[k];
  if (leaf(n)) {
    n.lo = lo_[n.begin];
    n.hi = hi_[n.begin];
    for (uint32_t e = n.begin + 1; e < n.end; ++e) {
      n.lo = glm::min(n.lo, lo_[e]);
      n.hi = glm::max(n.hi, hi_[e]);
    }
    return;
  }
  n.lo = glm::min(node_[k + 1].lo, node_[right_[k]].lo);
  n.hi = glm::max(node_[k + 1].hi, node_[right_[k]].hi);
}

std::vector<BoxTree::Task> BoxTree::pairTasks(float reach) const {
  std::vector<Task> tasks;
  if (!node_.empty()) gather(0, 0, reach, tasks);
  return tasks;
}

void BoxTree::gather(uint32_t a, uint32_t b, float reach, std::vector<Task>& tasks) const {
  const Node &na = node_[a], &nb = node_[b];
  if (a != b && !meet(na.lo, na.hi, nb.lo, nb.hi, reach)) return;
  const uint32_t boxes = (na.end - na.begin) + (a == b ? 0u : nb.end - nb.begin);
  if (boxes <= kTaskBoxes || (leaf(na) && leaf(nb))) {
    tasks.push_back(Task(a, b));
    return;
  }
  halves(a, b, [&](uint32_t c, uint32_t d) { gather(c, d, reach, tasks); });
}

} // namespace tender
