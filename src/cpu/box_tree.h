#pragma once
/// A tree of boxes (a bounding volume hierarchy) for the CPU contact's searches. A build splits a
/// node's boxes in two halves at the median of their centres along the widest side of the
/// centres' box, down to leaves of at most kLeaf boxes; later searches keep those groups and fit
/// their boxes anew (fit). A search descends only into the nodes whose boxes meet what it looks
/// for, so what it finds is the same whatever the groups: the boxes that meet a box (visit), or
/// every pair of boxes within a reach of each other on each axis, met once (pairTasks, then
/// visitPairs for each task, from any thread).
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace tender {

class WorkerPool;

class BoxTree {
public:
  /// A share of the pair search: the pairs within node `a` (a == b) or between nodes a and b.
  using Task = glm::uvec2;

  /// `min_chunk`: CpuOptions::min_chunk (1 builds and fits every tree from the pool's threads).
  explicit BoxTree(uint32_t min_chunk = 0) : shared_boxes_(min_chunk ? min_chunk : kSharedBoxes) {}

  /// The tree of boxes [lo[i], hi[i]]; with the pool's threads below its first two levels.
  void build(const std::vector<glm::vec3>& lo, const std::vector<glm::vec3>& hi, WorkerPool& pool);
  /// The tree of boxes [lo[i], hi[i]] in the last build's groups, their boxes fitted anew (built
  /// when the count of boxes changed). The groups need not be good for the searches to be right;
  /// they stay good while each moves as one, as a sheet's patches do while its edges barely stretch.
  void fit(const std::vector<glm::vec3>& lo, const std::vector<glm::vec3>& hi, WorkerPool& pool);
  /// Forgets the groups: the next fit builds.
  void clear() {
    node_.clear();
    id_.clear();
  }

  /// Calls f(i) for each box i that meets [lo, hi].
  template <class F>
  void visit(glm::vec3 lo, glm::vec3 hi, F&& f) const {
    if (node_.empty()) return;
    uint32_t stack[64], top = 0;
    stack[top++] = 0;
    while (top) {
      const uint32_t k = stack[--top];
      const Node& n = node_[k];
      if (!meet(lo, hi, n.lo, n.hi, 0.0f)) continue;
      if (leaf(n)) {
        for (uint32_t e = n.begin; e < n.end; ++e)
          if (meet(lo, hi, lo_[e], hi_[e], 0.0f)) f(id_[e]);
        continue;
      }
      stack[top++] = k + 1;
      stack[top++] = right_[k];
    }
  }

  /// Shares of the search for every pair of boxes within `reach` of each other (each in one of
  /// them), of at most about kTaskBoxes boxes each.
  std::vector<Task> pairTasks(float reach) const;

  /// Calls f(i, j) for each pair of boxes of `task` within `reach` of each other on each axis
  /// (i and j in no fixed order; over all the tasks of pairTasks, each pair once).
  template <class F>
  void visitPairs(Task task, float reach, F&& f) const {
    pairs(task.x, task.y, reach, f);
  }

  /// The bytes its arrays hold.
  uint64_t memoryBytes() const {
    return node_.capacity() * sizeof(Node) + parts_.capacity() * sizeof(Part) +
           (right_.capacity() + id_.capacity() + above_.capacity()) * sizeof(uint32_t) +
           (lo_.capacity() + hi_.capacity() + centre_.capacity()) * sizeof(glm::vec3);
  }

private:
  struct Node {
    glm::vec3 lo;
    uint32_t begin; ///< its boxes: the entries [begin, end) of lo_, hi_ and id_
    glm::vec3 hi;
    uint32_t end;
  };
  /// The most boxes a leaf holds, and about the most a task of pairTasks does
  static constexpr uint32_t kLeaf = 4, kTaskBoxes = 512;
  /// The fewest boxes whose subtrees the pool's threads build and fit (below, a fit takes tens of
  /// microseconds, about what handing it out costs)
  static constexpr uint32_t kSharedBoxes = 16384;
  /// Calls f(c) for each part c: from the pool's threads on a tree of shared_boxes_ boxes or
  /// more, else on the caller.
  template <class F>
  void eachPart(WorkerPool& pool, F&& f) const;

  static bool leaf(const Node& n) { return n.end - n.begin <= kLeaf; }
  /// True when the boxes [alo, ahi] and [blo, bhi] come within `reach` of each other on each axis.
  static bool meet(glm::vec3 alo, glm::vec3 ahi, glm::vec3 blo, glm::vec3 bhi, float reach) {
    return (alo.x - reach <= bhi.x) & (blo.x <= ahi.x + reach) & (alo.y - reach <= bhi.y) & (blo.y <= ahi.y + reach) &
           (alo.z - reach <= bhi.z) & (blo.z <= ahi.z + reach);
  }
  /// The nodes of a subtree of `boxes` boxes.
  static uint32_t nodeCount(uint32_t boxes) {
    return boxes <= kLeaf ? 1u : 1u + nodeCount(boxes / 2) + nodeCount(boxes - boxes / 2);
  }
  /// Sets node k to the entries [begin, end) and its second child, and splits them in two halves
  /// there (id_ reordered); gives where the second begins.
  uint32_t split(uint32_t k, uint32_t begin, uint32_t end);
  /// Builds node k over the entries [begin, end) (id_ set, in any order).
  void buildNode(uint32_t k, uint32_t begin, uint32_t end, const std::vector<glm::vec3>& lo,
                 const std::vector<glm::vec3>& hi);
  /// The node's box from its children's, or its leaf's boxes'.
  void fitNode(uint32_t k);
  /// The tasks of pairTasks for the pair of nodes (a, b), or for node a alone (a == b).
  void gather(uint32_t a, uint32_t b, float reach, std::vector<Task>& tasks) const;

  /// Calls go(c, d) for each pair of nodes that the pair (a, b) of nodes, not both leaves, splits
  /// into: a's halves, each alone and with the other (a == b), else the larger node's halves with
  /// the other node.
  template <class Go>
  void halves(uint32_t a, uint32_t b, Go&& go) const {
    const Node &na = node_[a], &nb = node_[b];
    if (a == b) {
      go(a + 1, a + 1);
      go(right_[a], right_[a]);
      go(a + 1, right_[a]);
    } else if (leaf(nb) || (!leaf(na) && na.end - na.begin >= nb.end - nb.begin)) {
      go(a + 1, b);
      go(right_[a], b);
    } else {
      go(a, b + 1);
      go(a, right_[b]);
    }
  }

  template <class F>
  void pairs(uint32_t a, uint32_t b, float reach, F& f) const {
    const Node &na = node_[a], &nb = node_[b];
    if (a != b && !meet(na.lo, na.hi, nb.lo, nb.hi, reach)) return;
    if (!leaf(na) || !leaf(nb)) return halves(a, b, [&](uint32_t c, uint32_t d) { pairs(c, d, reach, f); });
    // A leaf with itself (each pair once) or with another leaf
    for (uint32_t i = na.begin; i < na.end; ++i) {
      if (a != b && !meet(lo_[i], hi_[i], nb.lo, nb.hi, reach)) continue;
      for (uint32_t j = a == b ? i + 1 : nb.begin; j < nb.end; ++j)
        if (meet(lo_[i], hi_[i], lo_[j], hi_[j], reach)) f(id_[i], id_[j]);
    }
  }

  /// A subtree below the first two levels: its root, its entries [begin, end), and the end of its
  /// nodes [node, nodes) (set once it is split off)
  struct Part {
    uint32_t node, begin, end, nodes = 0;
  };
  uint32_t shared_boxes_;
  std::vector<Part> parts_;        ///< the subtrees the pool's threads build and fit, one each
  std::vector<uint32_t> above_;    ///< the nodes above them, each before its children
  std::vector<Node> node_;         ///< depth first: node k's children are k + 1 and right_[k]
  std::vector<uint32_t> right_;    ///< each inner node's second child
  std::vector<uint32_t> id_;       ///< the boxes in the leaves' order
  std::vector<glm::vec3> lo_, hi_; ///< their corners, in that order
  std::vector<glm::vec3> centre_;  ///< scratch: each box's centre (twice it), by its number
};

} // namespace tender
