#include "cpu_solver.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/denormal_mode.h"
#include "core/host_queries.h"
#include "settle_elements.h"
#include "simd_kernels.h"
#include "worker_pool.h"

namespace tender {

using namespace shaderio;

CpuSolver::CpuSolver(CpuOptions options)
    : options_(options), simd_(options.simd && simd::kBuilt),
      pool_(std::make_unique<WorkerPool>(options.threads, true)),
      collision_(*pool_, options.simd, options.candidate_lists),
      contact_(*pool_, CpuContact::Lists::Repaired, options.min_chunk) {}

// The constraints of each colour, reordered by their first particle, into one array per field
// (the SIMD kernels load them four or eight at a time). Constraints of one colour share no
// particle, so their order within the colour changes no result; this one makes the share of each
// worker a band of the sheet (the colours of the greedy colouring mix kinds, each in row order),
// so a worker keeps the same particles in its cache from colour to colour.
void CpuSolver::splitConstraints() {
  const size_t m = constraints_.size();
  std::vector<uint32_t> order(m);
  for (uint32_t k = 0; k < m; ++k) order[k] = k;
  // Within a colour (whose constraints share no particle, so any order gives the same bits): the
  // structural edges first, as the sheet has them (shortenColors visits that run alone), each run
  // by its first particle, for locality
  auto key = [&](uint32_t k) {
    return std::pair(constraintKind(constraints_[k]) != SIM_KIND_STRUCTURAL,
                     std::min(constraints_[k].a, constraints_[k].b));
  };
  for (const ColorRange& range : colors_)
    std::stable_sort(order.begin() + range.first, order.begin() + range.first + range.count,
                     [&](uint32_t x, uint32_t y) { return key(x) < key(y); });
  con_a_.resize(m);
  con_b_.resize(m);
  con_kind_.resize(m);
  con_id_.resize(m);
  con_rest_.resize(m);
  con_hinge_.assign(m, 0u);
  for (size_t k = 0; k < m; ++k) {
    const Constraint& c = constraints_[order[k]];
    con_a_[k] = c.a;
    con_b_[k] = c.b;
    con_kind_[k] = c.kind_id & SIM_KIND_MASK;
    con_id_[k] = c.kind_id >> SIM_KIND_BITS;
    con_rest_[k] = c.rest;
    if (con_kind_[k] != SIM_KIND_HINGE) continue;
    con_hinge_[k] = con_id_[k] - topo_->hinge_first;
  }
}

CpuSolver::~CpuSolver() = default;

uint32_t CpuSolver::threadCount() const { return pool_->size(); }

void CpuSolver::upload(const SheetTopology& topo) {
  topo_ = &topo;
  const uint32_t n = topo.particleCount();
  grain_ = Grain{options_.min_chunk, n < kSmallSheet};
  rest_ = topo.rest_pos;
  uv_ = topo.uv;
  limit_root_of_.clear(); // a new sheet: limitPass orders its rings again
  pos_.resize(n);
  for (uint32_t i = 0; i < n; ++i) pos_[i] = startPosition(rest_[i]);
  prev_ = pos_;
  normal_.assign(n, glm::vec4(0.0f, 0.0f, 1.0f, 0.0f));
  reset_from_ = pos_;
  constraints_ = topo.constraints;
  colors_ = topo.colors;
  splitConstraints();
  torn_.assign(topo.constraintCount(), 0u);
  hinges_.assign(topo.hingeCount(), vec4(0.0f));
  hinge_corners_.resize(4 * size_t(topo.hingeCount()));
  for (uint32_t k = 0; k < topo.hingeCount(); ++k) {
    const uvec4 q = gridHinge(k, topo.cols, topo.rows);
    for (uint32_t j = 0; j < 4; ++j) hinge_corners_[4 * size_t(k) + j] = q[j];
  }
  triangles_ = topo.triangles;
  contact_.invalidate();
  triangle_count_ = topo.triangleCount();
  ticks_ = 0;
  counters_ = {};
  stop_after_ = SIM_NONE;
  collision_.upload(topo.adj_offsets, topo.adj_list, topo.hash_size, grain_);
}

void CpuSolver::airPass(const SimUniforms& u) {
  air_.resize(pos_.size());
  SheetElements e = elements(u);
  pool_->parallelFor(uint32_t(pos_.size()), grain_(kGrainParticles), [&](uint32_t begin, uint32_t end) {
    for (uint32_t i = begin; i < end; ++i) air_[i] = vec4(e.airOnParticle(i), 0.0f);
  });
}

void CpuSolver::integrate(const SimUniforms& u, uint32_t s, bool air) {
  const float dt2 = u.dt * u.dt;
  const vec4 wind = u.wind[s], twist = u.wind_twist[s], target = u.grab_target[s], grab_prev = u.grab_prev[s];
  // integrateParticle in two loops: with the hand's pull in it, the step's loop cost twice as much
  const float damping = substepDamping(u.damping, u.verlet, s);
  pool_->parallelFor(uint32_t(pos_.size()), grain_(kGrainParticles), [&](uint32_t begin, uint32_t end) {
    vec4 *pos = pos_.data(), *prev = prev_.data();
    for (uint32_t i = begin; i < end; ++i) {
      const VerletState st =
          integrateOpenHand(pos[i], prev[i], rest_[i], uv_[i].x, i == u.grab_index, target, grab_prev, u.flags,
                            u.gravity, air ? windWithAir(wind, air_[i], u.flags) : wind, twist, damping, dt2);
      pos[i] = st.position;
      prev[i] = st.previous;
    }
    for (uint32_t i = begin; u.hand.reach > 0.0f && i < end; ++i) // the hand closed: its pull
      if (!placedByGrab(i == u.grab_index, target))
        pos[i] = handPull(pos[i], prev[i], i, vec3(target), u.hand, u.hand_motion);
  });
}

// Projects constraints [begin, end) of one colour (no two share a particle) in iteration
// `iteration`: the SIMD kernels project all but the last few distance constraints, the shaders'
// projectConstraint the rest (and a colour of hinges, which have colours of their own).
void CpuSolver::projectRange(SheetElements& e, const float stiffness[4], uint32_t iteration, uint32_t begin,
                             uint32_t end) {
  const uint32_t *ca = con_a_.data(), *cb = con_b_.data(), *kind = con_kind_.data(), *id = con_id_.data();
  const float* rest = con_rest_.data();
  const bool hinges = begin < end && kind[begin] == SIM_KIND_HINGE;
  uint32_t k = begin;
  if (simd_ && !hinges)
    k = simd::project(reinterpret_cast<float*>(pos_.data()), ca, cb, rest, kind, stiffness, begin, end);
  if (simd_ && hinges) {
    k = simd::projectHinges(reinterpret_cast<float*>(pos_.data()), reinterpret_cast<float*>(hinges_.data()),
                            hinge_corners_.data(), con_hinge_.data(), firstDiagonalHinge(topo_->cols, topo_->rows),
                            e.u.crease.compliance, begin, end);
  }
  for (; k < end; ++k)
    e.projectConstraint(Constraint{ca[k], cb[k], rest[k], (id[k] << SIM_KIND_BITS) | kind[k]}, iteration);
}

void CpuSolver::projectColors(const SimUniforms& u, uint32_t first, uint32_t count) {
  const float stiffness[4] = {u.stiffness.x, u.stiffness.y, u.stiffness.z, u.stiffness.w};
  const uint32_t colors = uint32_t(colors_.size());
  if (colors == 0) return;
  SheetElements e = elements(u);
  uint32_t largest = 0;
  for (const ColorRange& range : colors_) largest = std::max(largest, range.count);
  const uint32_t chunks = pool_->chunksFor(largest, grain_(kGrainConstraints));
  // Gauss-Seidel over colours: one phase per colour that projects in its iteration
  // (projectsInIteration), as many phases per job as fit.
  std::vector<uint32_t>& passes = project_passes_;
  passes.clear();
  for (uint32_t pass = first; pass < first + count; ++pass) {
    const ColorRange& range = colors_[pass % colors];
    if (range.count > 0 && projectsInIteration(con_kind_[range.first], pass / colors)) passes.push_back(pass);
  }
  const uint32_t total = uint32_t(passes.size());
  for (uint32_t done = 0; done < total; done += WorkerPool::kMaxPhases)
    pool_->runPhases(std::min(WorkerPool::kMaxPhases, total - done), chunks, [&](uint32_t phase, uint32_t chunk) {
      const uint32_t pass = passes[done + phase];
      const ColorRange& range = colors_[pass % colors];
      const uint32_t begin = WorkerPool::chunkBound(range.count, chunks, chunk);
      const uint32_t end = WorkerPool::chunkBound(range.count, chunks, chunk + 1);
      projectRange(e, stiffness, pass / colors, range.first + begin, range.first + end);
    });
}

const std::vector<uint32_t>& CpuSolver::countColourEdges() {
  // A colour holds its edges first (splitConstraints sorts them there; the compaction keeps the
  // order)
  const uint32_t* kind = con_kind_.data();
  colour_edges_.assign(colors_.size(), 0);
  for (size_t c = 0; c < colors_.size(); ++c) {
    const uint32_t* at = kind + colors_[c].first;
    colour_edges_[c] = uint32_t(
        std::partition_point(at, at + colors_[c].count, [](uint32_t k) { return k == SIM_KIND_STRUCTURAL; }) - at);
  }
  return colour_edges_;
}

void CpuSolver::shortenColors(const SimUniforms& u, uint32_t first, uint32_t count) {
  const uint32_t colors = uint32_t(colors_.size());
  SheetElements e = elements(u);
  // The stage visits the run of structural edges at the head of each colour alone
  const uint32_t *ca = con_a_.data(), *cb = con_b_.data(), *kind = con_kind_.data(), *id = con_id_.data();
  const float* rest = con_rest_.data();
  std::vector<uint32_t>& passes = project_passes_;
  const std::vector<uint32_t>& edges = countColourEdges();
  passes.clear();
  const uint32_t largest = *std::max_element(edges.begin(), edges.end());
  for (uint32_t pass = first; pass < first + count; ++pass) {
    const ColorRange& range = colors_[pass % colors];
    if (range.count > 0 && shortensColour(kind[range.first]) && edges[pass % colors] > 0) passes.push_back(pass);
  }
  const uint32_t chunks = pool_->chunksFor(largest, grain_(kGrainConstraints));
  const bool tears = tearingOn(u.tear_factor) && (u.tear_kinds & (1u << SIM_KIND_STRUCTURAL)) != 0u;
  const uint32_t total = uint32_t(passes.size());
  for (uint32_t done = 0; done < total; done += WorkerPool::kMaxPhases)
    pool_->runPhases(std::min(WorkerPool::kMaxPhases, total - done), chunks, [&](uint32_t phase, uint32_t chunk) {
      const uint32_t c = passes[done + phase] % colors, start = colors_[c].first;
      const uint32_t end = start + WorkerPool::chunkBound(edges[c], chunks, chunk + 1);
      uint32_t k = start + WorkerPool::chunkBound(edges[c], chunks, chunk);
      if (simd_)
        k = simd::shorten(reinterpret_cast<float*>(pos_.data()), ca, cb, rest, kind, u.limit.reach, u.tear_factor,
                          tears, k, end);
      for (; k < end; ++k) e.shortenConstraint(Constraint{ca[k], cb[k], rest[k], (id[k] << SIM_KIND_BITS) | kind[k]});
    });
}

void CpuSolver::creasePass(const SimUniforms& u) {
  SheetElements e = elements(u);
  pool_->parallelFor(u.hinge.count, grain_(kGrainConstraints), [&](uint32_t begin, uint32_t end) {
    uint32_t k = begin;
    if (simd_)
      k = simd::creaseHinges(reinterpret_cast<float*>(pos_.data()), reinterpret_cast<float*>(hinges_.data()),
                             hinge_corners_.data(), torn_.data() + u.hinge.first, u.crease.yield_angle,
                             u.crease.hardening, begin, end);
    for (; k < end; ++k) e.creaseHinge(k);
  });
}

void CpuSolver::limitPass(const SimUniforms& u) {
  SheetElements e = elements(u);
  // A particle's place depends on its parents' alone, so any order that places the parents first
  // gives the bits of the GPU's rings: row by row outwards from the root's row, each row outwards
  // from its column, one quadrant after the other (the root's row and column with the first
  // quadrants that reach them, before those that lean on them)
  const int cols = int(u.cols), rows = int(u.rows);
  const uvec4 roots = limitRootSet(u.limit_roots, u.grab_index, u.cols, u.rows);
  if (roots.w > 1u) {
    // Several roots: each particle around its own, in the order of its steps from it (a counting
    // sort; its parents are nearer their root, and so come first)
    const uint32_t n = uint32_t(pos_.size());
    std::vector<uint32_t>& root_of = limit_root_of_;
    std::vector<uint32_t>& order = limit_order_;
    if (limit_roots_ != roots || root_of.size() != n) { // the order stands while the sheet and roots do
      std::vector<uint32_t> start(limitRingsOf(roots, u.cols, u.rows) + 2u, 0u);
      root_of.resize(n);
      order.resize(n);
      auto ring = [&](uint32_t i) { return gridSteps(i, roots[int(root_of[i])], u.cols); };
      for (uint32_t i = 0; i < n; ++i) {
        root_of[i] = limitRootOf(i, roots, u.cols);
        ++start[ring(i) + 1u];
      }
      for (uint32_t k = 1; k < start.size(); ++k) start[k] += start[k - 1];
      for (uint32_t i = 0; i < n; ++i) order[start[ring(i)]++] = i;
      limit_first_ = start[0]; // ring 0 (the roots themselves) ends there
      limit_roots_ = roots;
    }
    for (uint32_t k = limit_first_; k < n; ++k) e.limitParticle(order[k], roots[int(root_of[order[k]])]);
    return;
  }
  const uint32_t root = roots.x;
  const int rx = int(root) % cols, ry = int(root) / cols;
  for (const int dy : {1, -1})
    for (const int dx : {1, -1})
      for (int y = dy > 0 ? ry : ry - 1; y >= 0 && y < rows; y += dy)
        for (int x = dx > 0 ? rx : rx - 1; x >= 0 && x < cols; x += dx)
          if (x != rx || y != ry) e.limitParticle(uint32_t(y * cols + x), root);
}

void CpuSolver::repelPass(const SimUniforms& u) {
  pool_->parallelFor(uint32_t(pos_.size()), grain_(kGrainParticles), [&](uint32_t begin, uint32_t end) {
    for (uint32_t i = begin; i < end; ++i) pos_[i] = repelParticle(pos_[i], collision_.delta(i), u.flags);
  });
}

void CpuSolver::floorPass(const SimUniforms& u, uint32_t s, bool contact) {
  const vec3 frame = contact ? contact_.frame() : vec3(0.0f);
  const uint32_t n = uint32_t(pos_.size());
  pool_->parallelFor(n, grain_(kGrainParticles), [&](uint32_t begin, uint32_t end) {
    for (uint32_t i = begin; i < end; ++i) {
      const VerletState st = floorContact(pos_[i], prev_[i], u.floor_y, u.restitution, u.friction);
      pos_[i] = st.position;
      prev_[i] = st.previous;
    }
  });
  if (!contact) return;
  // What each step is passed by its pairs, its excess beyond their half-spaces and the share that
  // keeps them, then each step with what it is passed cut to them and to its bound
  contact_.slide(start_, pos_, u, passed_, excess_, share_);
  pool_->parallelFor(n, grain_(kGrainParticles), [&](uint32_t begin, uint32_t end) {
    for (uint32_t i = begin; i < end; ++i) {
      if (!contactBounded(pos_[i].w, i == u.grab_index, u.grab_target[s].w)) continue;
      const VerletState passed = passedState(VerletState{pos_[i], prev_[i]}, vec3(passed_[i]), u.floor_y);
      const VerletState st =
          slideStep(passed, vec3(start_[i]), vec3(push_[i]), vec3(excess_[i]), share_[i], bound_[i], frame);
      pos_[i] = st.position;
      prev_[i] = st.previous;
    }
  });
}

// The settle sweeps, after the contact's cut and push (settle_bodies.h): over the structural edges
// of each colour, contact_check.sweeps times; none when no edge is over the limit, and no more after a
// sweep that moved nothing (the next would move nothing either: the bits are the same).
void CpuSolver::settlePass(const SimUniforms& u, uint32_t s) {
  const uint32_t colors = uint32_t(colors_.size());
  const uint32_t *ca = con_a_.data(), *cb = con_b_.data(), *kind = con_kind_.data(), *id = con_id_.data();
  const float* rest = con_rest_.data();
  const std::vector<uint32_t>& edges = countColourEdges();
  auto at = [&](uint32_t k) { return Constraint{ca[k], cb[k], rest[k], (id[k] << SIM_KIND_BITS) | kind[k]}; };
  SettleElements e{u,       pos_.data(), prev_.data(), start_.data(),   push_.data(), bound_.data(),
                   nullptr, nullptr,     nullptr,      contact_.frame()};
  // Sweeps the colours' edges with `body` in one job, a phase a colour with edges (shared on a small
  // sheet too: a sweep costs about a projection iteration); true when it returned true for one
  settle_colours_.clear();
  uint32_t largest = 0;
  for (uint32_t c = 0; c < colors; ++c)
    if (edges[c] > 0) settle_colours_.push_back(c);
  for (const uint32_t c : settle_colours_) largest = std::max(largest, edges[c]);
  const uint32_t chunks = pool_->chunksFor(largest, grain_.heavy(kGrainSettle));
  auto sweep = [&](auto&& body) {
    std::atomic<bool> any{false};
    pool_->runPhases(uint32_t(settle_colours_.size()), chunks, [&](uint32_t phase, uint32_t chunk) {
      const uint32_t c = settle_colours_[phase];
      const uint32_t first = colors_[c].first, begin = WorkerPool::chunkBound(edges[c], chunks, chunk),
                     end = WorkerPool::chunkBound(edges[c], chunks, chunk + 1);
      bool mine = false;
      for (uint32_t k = first + begin; k < first + end; ++k) mine = body(at(k)) || mine;
      if (mine) any.store(true, std::memory_order_relaxed);
    });
    return any.load();
  };
  if (!sweep([&](Constraint c) { return e.settleOver(c, s); })) return;
  contact_.listHalfSpaces(uint32_t(pos_.size()));
  e.half_start = contact_.halfStart().data();
  e.half_spaces = contact_.halfSpaces().data();
  e.half_slack = contact_.halfSlack().data();
  for (uint32_t k = 0; k < u.contact_check.sweeps; ++k)
    if (!sweep([&](Constraint c) { return e.settleConstraint(c, s); })) break;
}

SheetElements CpuSolver::elements(const SimUniforms& u) {
  return SheetElements{
      u, pos_.data(), prev_.data(), SharedWords{torn_.data()}, topo_->tri_edges.data(), hinges_.data(), counters_};
}

void CpuSolver::resetPass(const SimUniforms& u) {
  pool_->parallelFor(uint32_t(pos_.size()), grain_(kGrainParticles), [&](uint32_t begin, uint32_t end) {
    for (uint32_t i = begin; i < end; ++i) {
      const float w = inverseMass(rest_[i], false, u.flags);
      pos_[i] = vec4(blend3(vec3(reset_from_[i]), vec3(rest_[i]), u.reset_alpha), w);
      prev_[i] = pos_[i];
    }
  });
}

Arithmetic CpuSolver::arithmetic() const {
  Arithmetic a;
  a.denormals = "flush to zero (FTZ, DAZ)";
  return a;
}

void CpuSolver::tick(const SimUniforms& u) {
  const DenormalMode mode(true);
  const uint32_t stop = stop_after_;
  stop_after_ = SIM_NONE;
  const uint64_t tick = ticks_++;
  if (u.reset_active) {
    resetPass(u);
    passes_per_tick_ = 1;
    return;
  }
  const uint32_t when = conditionsOf(u); // the stages that run (stageConditions)
  contact_on_ = runsWhen(SIM_WHEN_CONTACT, when);
  std::optional<uint32_t> plant_at;
  if (plant_ && plant_->tick == tick) plant_at = passIndex(u, plant_->pass);
  const uint32_t plant = plant_at.value_or(SIM_NONE);
  uint32_t pass = 0; // the tick's next pass (passes.h numbering)
  // Ends the next `count` passes; true when the tick stops after them.
  auto passed = [&](uint32_t count) {
    pass += count;
    if (plant == pass - 1 && plant_->particle < pos_.size()) {
      float& x = pos_[plant_->particle].x;
      x = std::nextafter(x, INFINITY);
    }
    return stop == pass - 1;
  };
  // The stages of each substep in their order (SIM_STAGES), those whose conditions hold, a stage of
  // several passes (one per colour of each iteration) in runs that end where the tick stops or a
  // change is planted
  for (uint32_t s = 0; s < substepCount(u.substeps); ++s)
    for (uint32_t stage = 0; stage < SIM_STAGE_COUNT; ++stage) {
      const uint32_t passes = stagePasses(stage, u.iterations, uint32_t(colors_.size()), when);
      for (uint32_t done = 0; done < passes;) {
        uint32_t run = passes - done;
        for (uint32_t cut : {stop, plant})
          if (cut >= pass && cut - pass < run) run = cut - pass + 1;
        runStage(PassKind(stage), u, when, s, done, run);
        done += run;
        if (passed(run)) return;
      }
    }
  passes_per_tick_ = passesPerTick(u);
}

void CpuSolver::runStage(PassKind stage, const SimUniforms& u, uint32_t when, uint32_t s, uint32_t first,
                         uint32_t count) {
  switch (stage) {
  case PassKind::contact: // the step bounds of the substep, from where the particles start it
    contact_.computeBounds(pos_, prev_, triangles_, triangle_count_, u, s, bound_, push_);
    start_ = pos_;
    break;
  case PassKind::air:
    airPass(u); // the air on each particle, which the integration reads
    break;
  case PassKind::integrate:
    integrate(u, s, runsWhen(SIM_WHEN_AIR, when)); // damped Verlet, gravity, wind; pins and the grab hold
    break;
  case PassKind::project:
    projectColors(u, first, count); // Gauss-Seidel over the colours
    break;
  case PassKind::shorten:
    shortenColors(u, first, count); // while nothing holds the sheet, over-long edges shortened
    break;
  case PassKind::limit:
    limitPass(u); // no structural edge longer than the limit
    break;
  case PassKind::crease:
    creasePass(u); // hinges bent past their yield move their rest angles
    break;
  case PassKind::collide:
    collide(u);   // repulsion of unconnected neighbours (Jacobi)
    repelPass(u); // which the free particles take before the projection
    break;
  case PassKind::floor:
    floorPass(u, s, runsWhen(SIM_WHEN_CONTACT, when)); // the ground contact; with contact, the steps cut
    break;
  case PassKind::settle:
    settlePass(u, s); // over-long edges shortened within the steps' bounds
    break;
  case PassKind::tear:
    // Tear, let go of what stood on the triangles lost, compact the colours and triangles
    if (markTears(u) > 0) {
      markUnsupported(u);
      compact();
    }
    break;
  case PassKind::reset:
    resetPass(u);
    break;
  }
}

void CpuSolver::beginReset() {
  reset_from_ = pos_;
  constraints_ = topo_->constraints;
  colors_ = topo_->colors;
  splitConstraints();
  std::fill(torn_.begin(), torn_.end(), 0u);
  std::fill(hinges_.begin(), hinges_.end(), vec4(0.0f));
  triangles_ = topo_->triangles;
  contact_.invalidate();
  triangle_count_ = topo_->triangleCount();
}

void CpuSolver::computeNormals() {
  const DenormalMode mode(true);
  gridNormals(pos_, topo_->cols, topo_->rows, normal_);
}

PickResult CpuSolver::pick(glm::vec3 o, glm::vec3 d, float radius) {
  const DenormalMode mode(true);
  return pickNearest(pos_, o, d, radius);
}

void CpuSolver::readDeltas(std::vector<glm::vec4>& out) {
  out.assign(pos_.size(), vec4(0.0f));
  if (collision_.slotDeltas().size() < pos_.size()) return; // no collide pass yet
  for (uint32_t i = 0; i < pos_.size(); ++i) out[i] = vec4(collision_.delta(i), 0.0f);
}

void CpuSolver::readback(SimState& out) {
  out.pos = pos_;
  out.prev = prev_;
  out.normal = normal_;
  out.constraints = constraints_;
  out.colors = colors_;
  out.torn = torn_;
  out.hinges = hinges_;
  out.triangles.assign(triangles_.begin(), triangles_.begin() + triangle_count_);
  out.triangle_count = triangle_count_;
}

uint64_t CpuSolver::memoryBytes() const {
  return capacityBytes(pos_) + capacityBytes(prev_) + capacityBytes(rest_) + capacityBytes(normal_) +
         capacityBytes(reset_from_) + capacityBytes(uv_) + capacityBytes(constraints_) + capacityBytes(colors_) +
         capacityBytes(torn_) + capacityBytes(hinges_) + capacityBytes(con_a_) + capacityBytes(con_b_) +
         capacityBytes(con_kind_) + capacityBytes(con_id_) + capacityBytes(con_rest_) + capacityBytes(con_hinge_) +
         capacityBytes(hinge_corners_) + capacityBytes(triangles_) + collision_.memoryBytes() + contact_.memoryBytes() +
         capacityBytes(start_) + capacityBytes(bound_) + capacityBytes(push_) + capacityBytes(passed_) +
         capacityBytes(excess_) + capacityBytes(share_);
}

} // namespace tender
