#pragma once
/// Penetration-free self-contact of the CPU solver: the step bound of every particle at the start
/// of a substep (contact.h: slideBound, from the nearest of the triangles and edges near it) and,
/// after the floor, the cut of each step to its pairs' half-spaces (slide), from lists of the
/// pairs near each other that a tree of the triangles' boxes finds (each two triangles near each
/// other, the pairs of the edges and particles they own), kept while the particles travel
/// little (once the sheet's turn is taken out, and where clusters of them next to each other
/// travel alike) and repaired where a few travelled far. Each distance lowers
/// the bounds of the particles of its pair by an atomic minimum, and each half-space their shares
/// (their excesses are integer sums), so the bits are the same whatever the thread count or order
/// and whatever the lists hold beyond the pairs closer than the radius.
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "box_tree.h"
#include "shaderio.h"

namespace tender {

class WorkerPool;

class CpuContact {
public:
  /// How the pair lists are kept; the bounds and pushes are the same bits either way.
  enum class Lists {
    Rebuilt, ///< built whole at every call (the tests' reference)
    Repaired ///< kept while they hold every pair that can touch (the travels, turned, clusters), else
             ///< repaired where a few particles travelled too far, else built whole
  };
  /// `min_chunk`: CpuOptions::min_chunk (1 splits every search tree's build among the threads).
  CpuContact(WorkerPool& pool, Lists lists, uint32_t min_chunk = 0)
      : pool_(pool), lists_kept_(lists), tree_(min_chunk) {}

  /// The step bound of each particle at `pos` (xyz; w inverse mass; `prev` where each was a
  /// substep before) in substep `s`, of the sheet made of the first `count` triangles of
  /// `triangles` (xyz: their particles), for the contact of `u` (SimUniforms::contact,
  /// contact_check), into `bound`, and in `push` the push that parts the pairs closer than the
  /// thickness (contactPush, averaged over a particle's pairs); the frame of the substep's steps
  /// (contactFrame) in frame(). The edges are worked out again when the triangles change (a tear).
  void computeBounds(const std::vector<glm::vec4>& pos, const std::vector<glm::vec4>& prev,
                     const std::vector<glm::uvec4>& triangles, uint32_t count, const shaderio::SimUniforms& u,
                     uint32_t s, std::vector<float>& bound, std::vector<glm::vec4>& push);
  /// The half-spaces of the pairs of the last computeBounds on the steps of the substep (the
  /// particles from `start`, where that call had them, to `pos`, less frame()): what each particle
  /// is passed of the excess of the steps of its pairs' other primitives, the mean of
  /// contactPassed, into `passed`; the excess of its step with that (passedPosition) beyond them,
  /// the mean of slideExcess over its pairs, into `excess`; and the share of that step with the
  /// excess taken out that keeps every one, the least slideShare, into `share` (slideStep).
  void slide(const std::vector<glm::vec4>& start, const std::vector<glm::vec4>& pos, const shaderio::SimUniforms& u,
             std::vector<glm::vec4>& passed, std::vector<glm::vec4>& excess, std::vector<float>& share);
  /// Lists each of the `particles` particles' half-spaces of the last computeBounds's pairs (those
  /// slide cuts the steps to, where that call had the particles) for the settle stage.
  void listHalfSpaces(uint32_t particles);
  /// The lists of listHalfSpaces: particle i's half-spaces (SlideHalf::h, and their slack) from
  /// halfStart()[i] to halfStart()[i + 1], in no fixed order (settle_bodies.h takes minimums).
  const std::vector<uint32_t>& halfStart() const { return half_start_; }
  const std::vector<glm::vec4>& halfSpaces() const { return half_; }
  const std::vector<float>& halfSlack() const { return half_slack_; }
  /// The translation taken out of the steps of the substep of the last call before their bounds.
  glm::vec3 frame() const { return frame_; }
  /// Particles within the radius of a primitive at the last call.
  uint64_t contacts() const { return contacts_; }
  /// The times the pair lists were built whole.
  uint32_t listBuilds() const { return builds_; }
  /// The substeps whose pair lists stood only once the sheet's turn was taken out of the travels
  /// (turnedTravel).
  uint32_t listTurns() const { return turns_; }
  /// The substeps whose pair lists stood only by the clusters' travels (clustersHold).
  uint32_t listHolds() const { return held_; }
  /// The times the pair lists were repaired: the pairs of the particles that travelled too far
  /// looked for again (repairLists).
  uint32_t listRepairs() const { return repairs_done_; }
  /// True when the sheet crossed itself at the last call (the particles of the crossing triangles
  /// went unbounded to untangle it).
  bool crossedItself() const { return tangles_; }
  /// Forgets the edges (a new sheet or a reset).
  void invalidate() {
    edges_key_ = ~0ull;
    lists_ = false;
    free_.clear();
    tangles_ = false;
    tree_.clear();
  }
  uint64_t memoryBytes() const;

private:
  /// Shares a worker takes of a list build's search tasks (BoxTree::pairTasks): a crumpled part of
  /// the sheet costs more than a flat one
  static constexpr uint32_t kSearchShares = 8;

  /// Calls visit(pair, NearestPoints, edge, j, SlideHalf) for each half-space the pairs closer than
  /// the radius set their particles (particle j of the pair) where computeBounds had them (as
  /// lowerNearest weighed them), from the pool's threads.
  template <class Visit>
  void visitHalfSpaces(Visit&& visit);
  /// Box tests below which the crossing check tests its triangles against every triangle
  static constexpr uint64_t kBruteForceTests = 1u << 20;
  /// Adds a push to particle i's sum in fixed point (contactFixed, `scale` units a unit of length)
  /// and counts it; from any thread (the integer sums give the same bits in any order).
  static void addFixed(std::vector<glm::ivec4>& sums, uint32_t i, glm::vec3 v, float scale);
  /// Sets free_ to the particles of the triangles that cross another, among the pairs with one of
  /// the triangles crossingChecked names (contact.h), and adds each crossing pair's untanglePush to
  /// the sums (`gap`: how far beyond, `scale`: their fixed point); the last call's free_ is was_free_.
  void findCrossings(const std::vector<glm::vec4>& pos, const std::vector<glm::uvec4>& triangles, uint32_t count,
                     bool all, float gap, float scale);
  /// The substep's contact frame (frame_) from every particle's last step; gives the lowest and
  /// highest travel since the lists were built.
  std::pair<glm::vec3, glm::vec3> gatherFrame(const std::vector<glm::vec4>& pos, const std::vector<glm::vec4>& prev,
                                              const shaderio::SimUniforms& u, uint32_t s);
  /// The mesh's edges (edges_) from the first `count` triangles; the lists must be built again.
  void listEdges(const std::vector<glm::uvec4>& triangles, uint32_t count);
  /// Keeps the pair lists for this substep's positions: as they are, repaired or built anew.
  void keepLists(const std::vector<glm::vec4>& pos, const std::vector<glm::uvec4>& triangles, uint32_t count,
                 float radius, glm::vec3 travel_lo, glm::vec3 travel_hi);
  /// Each particle's nearest pair's squared distance under the radius (nearest2_), the half-spaces
  /// of the pairs closer than it (weighed_, near_; slideConstraint with `fraction`), and the pushes
  /// of the pairs closer than `thickness` into sums_.
  void lowerNearest(const std::vector<glm::vec4>& pos, float radius, float thickness, float scale, float fraction);
  /// Lists the particle-triangle and edge-edge pairs closer than contactReach at `pos`.
  void buildLists(const std::vector<glm::vec4>& pos, const std::vector<glm::uvec4>& triangles, uint32_t count,
                  float radius);
  /// Repairs the lists when few particles travelled more than contactTravel from `middle`, the
  /// travel most share: drops every pair with such a particle, lists those closer than
  /// contactRepairReach anew and moves their particles' bases so that they travelled `middle`.
  /// False (nothing changed) when too many did.
  bool repairLists(const std::vector<glm::vec4>& pos, const std::vector<glm::uvec4>& triangles, uint32_t count,
                   float radius);
  /// Marks the particles that travelled more than contactTravel from the travel most share
  /// (moved_, dirty_) and gives that travel, or nothing when none or too many did.
  std::optional<glm::vec3> markMoved(const std::vector<glm::vec4>& pos, float radius);
  /// Lists anew the pairs closer than `reach` with a moved particle into added_vf and added_ee.
  void searchMoved(const std::vector<glm::vec4>& pos, const std::vector<glm::uvec4>& triangles, uint32_t count,
                   float reach, std::vector<glm::uvec4>& added_vf, std::vector<glm::uvec4>& added_ee);
  /// Each particle's travel since its base in the frame of the sheet's turn since, into travel_:
  /// R^T (x - c) - (b - c') for the rotation R that best carries the bases (b, centroid c') onto
  /// the positions (x, centroid c), so that a sheet swinging about its pins travels as little as
  /// one at rest; the componentwise lowest and highest of them.
  std::pair<glm::vec3, glm::vec3> turnedTravel(const std::vector<glm::vec4>& pos);
  /// Sorts the particles into clusters by the cells of a grid kClusterWidth x (reach + longest
  /// edge) wide of their bases: cluster_members_, cluster_start_, cluster_pairs_ (each with itself
  /// and the clusters in the 26 cells around it), cluster_far_.
  void clusterBases(float radius);
  /// True when the pair lists still hold every pair closer than the radius although the travels
  /// (travel_, componentwise lowest `lo` and highest `hi`) outgrew one point: the travels of
  /// each two clusters next to each other lie within two contactTravel, and the whole spread
  /// within cluster_far_.
  bool clustersHold(glm::vec3 lo, glm::vec3 hi, float radius);
  /// The boxes of the first `count` triangles at `pos` into lo_ and hi_, their balls into ball_,
  /// and the edges' middles and sides into segment_.
  void boxTriangles(const std::vector<glm::vec4>& pos, const std::vector<glm::uvec4>& triangles, uint32_t count);
  /// The pairs within `reach` between what triangles t and o own that `keep` takes (buildLists).
  template <class Keep>
  void pairsOfTriangles(uint32_t t, uint32_t o, const std::vector<glm::vec4>& pos,
                        const std::vector<glm::uvec4>& triangles, float reach, Keep&& keep, std::vector<glm::uvec4>& vf,
                        std::vector<glm::uvec4>& ee) const;
  /// Particle v, which no triangle holds, against the triangles within `reach` (tree_ of them).
  void searchLoner(uint32_t v, const std::vector<glm::vec4>& pos, const std::vector<glm::uvec4>& triangles, float reach,
                   std::vector<glm::uvec4>& vf) const;
  /// What each triangle owns for buildLists's search (own_, own_particles_, owned_).
  void ownTriangles(const std::vector<glm::uvec4>& triangles, uint32_t count);
  /// False when the positions have gone wrong: an edge's squared length is not finite.
  bool searchable(const std::vector<glm::vec4>& pos) const;

  /// A cluster's width, in reaches and longest edges
  static constexpr float kClusterWidth = 4.0f;
  /// A repair looks for the pairs of at most 1 / kRepairShare of the particles; more build whole
  static constexpr uint32_t kRepairShare = 8;

  WorkerPool& pool_;
  Lists lists_kept_;
  std::vector<glm::uvec4> vf_;     ///< particle, then the triangle's three: pairs within radius + skin
  std::vector<glm::ivec4> sums_;   ///< each particle's pushes in fixed point, and their count
  std::vector<glm::uvec4> ee_;     ///< two edges' particles: pairs within radius + skin
  std::vector<glm::vec4> base_;    ///< where the particles were when the lists were built
  bool lists_ = false;             ///< the lists are usable
  std::vector<uint8_t> free_;      ///< particles of triangles crossing another: not bounded
  std::vector<uint8_t> was_free_;  ///< free_ of the last call
  std::vector<uint32_t> checked_;  ///< scratch: the triangles checked for crossing
  std::vector<uint8_t> crossing_;  ///< scratch: the triangles crossing another
  bool tangles_ = false;           ///< the sheet crossed itself at the last call
  float list_radius_ = 0.0f;       ///< the contact radius they were built for
  std::vector<glm::uvec2> edges_;  ///< the sheet's edges, each once (a < b)
  uint64_t edges_key_ = ~0ull;     ///< the triangle count the edges were worked out for
  std::vector<glm::vec3> lo_, hi_; ///< scratch: the boxes of the triangles
  std::vector<glm::vec4> ball_;    ///< scratch: the triangles' balls (centroid, farthest corner)
  /// An edge's middle and its side (second particle less first), for segmentsApart
  struct Segment {
    glm::vec3 middle, side;
  };
  std::vector<Segment> segment_;        ///< scratch: each edge's, by its number
  std::vector<glm::uvec4> own_;         ///< each triangle's own edges and counts (ownTriangles)
  std::vector<uint32_t> own_particles_; ///< each triangle's own particles, three slots a triangle
  std::vector<uint8_t> owned_;          ///< the particles some triangle holds
  std::vector<uint8_t> moved_;          ///< scratch: the particles a repair looks at
  std::vector<float> travels_;          ///< scratch: one component of every particle's travel
  std::vector<uint32_t> dirty_;         ///< scratch: the particles, then the triangles, a repair looks at
  std::vector<uint32_t> nearest2_;      ///< the bits of each particle's smallest squared distance
  /// A pair closer than the radius where computeBounds had its particles: its nearest points and
  /// the half-space it sets each of them
  struct Weighed {
    shaderio::NearestPoints c;
    shaderio::SlideHalf h[4];
  };
  std::vector<Weighed> weighed_;     ///< each pair of vf_, then of ee_, where near_ marks it
  std::vector<uint8_t> near_;        ///< the pairs closer than the radius with no free particle
  std::vector<uint32_t> share_bits_; ///< scratch: the bits of each particle's share (slide)
  std::vector<uint32_t> half_start_; ///< each particle's half-spaces at [half_start_[i], half_start_[i + 1])
  std::vector<glm::vec4> half_;      ///< the half-spaces (SlideHalf::h)
  std::vector<float> half_slack_;    ///< and their slack
  std::vector<uint32_t> half_fill_;  ///< scratch: where each particle's next half-space goes
  BoxTree tree_;                     ///< the triangles' boxes at the last search
  uint64_t contacts_ = 0;
  uint32_t builds_ = 0;
  uint32_t repairs_done_ = 0;
  uint32_t turns_ = 0;
  uint32_t held_ = 0;
  size_t built_pairs_ = 0; ///< the pairs the last build listed
  glm::vec3 frame_{0.0f};

  // The travels in the turned frame and the clusters (turnedTravel, clustersHold)
  std::vector<glm::vec3> travel_;         ///< each particle's travel in the turned frame
  glm::dquat turn_{1.0, 0.0, 0.0, 0.0};   ///< the sheet's turn since the lists were built, last fitted
  std::vector<uint32_t> cluster_members_; ///< the particles, a cluster's together
  std::vector<uint32_t> cluster_start_;   ///< where each cluster's particles start in cluster_members_
  std::vector<glm::uvec2> cluster_pairs_; ///< clusters next to each other (or one twice), each pair once
  std::vector<glm::vec4> cluster_box_;    ///< scratch: each cluster's travels' middle (xyz) and half-diagonal
  uint32_t cluster_count_ = 0;
  float cluster_far_ = 0.0f;   ///< the spread of the travels that clusters apart allow
  uint32_t cluster_key_ = ~0u; ///< builds + repairs when the clusters were made
};

} // namespace tender
