// The per-colour path records a substep as the pass table says (SIM_STAGES, SIM_DISPATCHES in
// shaders/shared/sim_passes.h): the stages in their numbered order, every pass of a stage its
// dispatches, a timestamp where each category ends, and a tick cut short after pass k records the
// dispatches of passes 0..k and nothing more. No device: the sink only writes down what it is given.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "common/sim_helpers.h"
#include "core/passes.h"
#include "core/sheet.h"
#include "gpu/substep_passes.h"

using namespace tender;
using namespace tender::gpu;

namespace {

struct Recorded {
  std::string kernel;
  PassGate gate;
};

/// Writes down each pass (by kernel name), barrier and mark.
class RecordingSink final : public PassSink {
public:
  explicit RecordingSink(const SimPipelines& pipes) {
#define NAME_OF(name, push, per_invocation, batched) names_.emplace_back(pipes.name.pipeline, #name);
    SIM_KERNELS(NAME_OF)
#undef NAME_OF
  }
  void pass(const ComputePipeline& p, Grid, uint32_t, const void*, uint32_t, uint32_t, const PassGate& gate) override {
    for (const auto& [pipeline, name] : names_)
      if (pipeline == p.pipeline) passes.push_back({name, gate});
    ++barriers_due;
  }
  void barrier() override { barriers_due = 0; }
  void mark(PassCategory c) override { marks.push_back(c); }

  std::vector<Recorded> passes;
  std::vector<PassCategory> marks;
  uint32_t barriers_due = 0; ///< passes recorded since the last barrier

private:
  std::vector<std::pair<VkPipeline, std::string>> names_;
};

/// Pipelines with distinct (never dispatched) handles, each of a CPU device's workgroup (the
/// stretch limit's dispatches follow it).
SimPipelines fakePipelines() {
  SimPipelines pipes;
  uintptr_t handle = 1;
#define FAKE(name, push, per_invocation, batched)                                                                      \
  pipes.name.pipeline = reinterpret_cast<VkPipeline>(handle++);                                                        \
  pipes.name.workgroup = SIM_WG_LIMIT;
  SIM_KERNELS(FAKE)
#undef FAKE
  return pipes;
}

std::vector<std::string> kernels(const std::vector<Recorded>& passes) {
  std::vector<std::string> names;
  for (const Recorded& r : passes) names.push_back(r.kernel);
  return names;
}

/// The topology of a `cols` x `rows` tender sheet with hinges.
SheetTopology tenderSheet(uint32_t cols, uint32_t rows) {
  SimParams p = test::clothWithContact({"dihedral=on"});
  p.cols = cols;
  p.rows = rows;
  return buildSheet(p);
}

/// Its layout on a device that binds 128 MiB.
SheetLayout layoutOf(const SheetTopology& topo) { return SheetLayout::of(topo, VkDeviceSize(1) << 27); }

} // namespace

TEST(SubstepPasses, RecordsTheStagesInOrderWithATimestampPerCategory) {
  const SheetTopology topo = tenderSheet(8, 6);
  const SheetLayout sizes = SheetLayout::of(topo, VkDeviceSize(1) << 27, true);
  const SimPipelines pipes = fakePipelines();
  RecordingSink sink(pipes);
  uint32_t pass = 0;
  constexpr uint32_t all = SIM_WHEN_COLLISION | SIM_WHEN_AIR | SIM_WHEN_CONTACT | SIM_WHEN_LIMIT | SIM_WHEN_SHORTEN |
                           SIM_WHEN_CREASE | SIM_WHEN_SETTLE;
  const SubstepPlan plan{2, all, SIM_NONE, 2};
  EXPECT_FALSE(recordSubstep(sink, pipes, topo, sizes, plan, 0, pass));
  EXPECT_EQ(pass, shaderio::passesPerSubstep(2, topo.colorCount(), all));
  EXPECT_EQ(sink.barriers_due, 0u); // every pass is followed by a barrier

  // The contact's grid (its buckets' scan one block here), then the integration
  ASSERT_LE(sizes.contact_buckets + 1, SIM_SCAN_BLOCK);
  std::vector<std::string> expected = {
      "contact_begin",   "contact_clear", "contact_arm",  "contact_grid_clear", "contact_count", "scan",
      "contact_scatter", "contact_cross", "contact_near", "contact_active",     "scan",          "contact_emit",
      "contact_walk",    "contact_bound", "air",          "integrate"};
  // The repulsion, which the particles take before the projection
  for (const char* k : {"candidates_check", "candidates_decide", "hash_count", "scan", "hash_scatter", "hash_sort",
                        "collide", "candidates_finish", "repel"})
    expected.push_back(k);
  std::vector<uint32_t> iterations;
  // Every colour with constraints in the first iteration; in the second, all but the hinges'. A
  // hinge colour has a kernel of its own.
  uint32_t hinge_colors = 0;
  for (const ColorRange& range : topo.colors)
    hinge_colors += range.count > 0 && constraintKind(topo.constraints[range.first]) == SIM_KIND_HINGE ? 1 : 0;
  EXPECT_GT(hinge_colors, 0u);
  for (uint32_t it = 0; it < 2; ++it)
    for (const ColorRange& range : topo.colors) {
      const bool hinges = constraintKind(topo.constraints[range.first]) == SIM_KIND_HINGE;
      if (range.count > 0 && (it == 0 || !hinges)) {
        expected.push_back(hinges ? "project_hinge" : "project");
        iterations.push_back(it);
      }
    }
  // The shorten stage: in each iteration every colour that holds edges (they come first)
  std::vector<uint32_t> shorten_iterations;
  for (uint32_t it = 0; it < 2; ++it)
    for (const ColorRange& range : topo.colors)
      if (range.count > 0 && constraintKind(topo.constraints[range.first]) == SIM_KIND_STRUCTURAL) {
        expected.push_back("shorten");
        shorten_iterations.push_back(it);
      }
  expected.push_back("limit");
  // The floor, then the steps cut to their pairs' half-spaces
  for (const char* k : {"floor", "contact_pass", "contact_excess", "contact_share", "contact_step"})
    expected.push_back(k);
  // The settle: whether an edge is over the limit, the half-spaces counted by particle, scanned (one
  // block here) and listed, then in each sweep every colour that holds edges
  ASSERT_LE(topo.particleCount() + 1, SIM_SCAN_BLOCK);
  for (const char* k : {"contact_settle_check", "contact_half_count", "scan", "contact_half_fill"})
    expected.push_back(k);
  for (uint32_t sweep = 0; sweep < 2; ++sweep)
    for (const ColorRange& range : topo.colors)
      if (range.count > 0 && constraintKind(topo.constraints[range.first]) == SIM_KIND_STRUCTURAL)
        expected.push_back("contact_settle");
  expected.push_back("crease"); // on where the sheet went
  for (const char* k : {"tear_mark", "tear_unsupported", "tear_flags", "scan", "tear_compact"}) expected.push_back(k);
  EXPECT_EQ(kernels(sink.passes), expected);
  for (size_t k = 0, project = 0, shorten = 0; k < sink.passes.size(); ++k)
    if (sink.passes[k].kernel == "project" || sink.passes[k].kernel == "project_hinge") {
      EXPECT_EQ(sink.passes[k].gate.when, SIM_WHEN_ALWAYS);
      EXPECT_EQ(sink.passes[k].gate.live, SIM_LIVE_ITERATION);
      EXPECT_EQ(sink.passes[k].gate.arg, iterations[project++]);
    } else if (sink.passes[k].kernel == "shorten") {
      EXPECT_EQ(sink.passes[k].gate.when, SIM_WHEN_SHORTEN);
      EXPECT_EQ(sink.passes[k].gate.live, SIM_LIVE_ITERATION);
      EXPECT_EQ(sink.passes[k].gate.arg, shorten_iterations[shorten++]);
    } else if (sink.passes[k].kernel == "contact_step") {
      EXPECT_EQ(sink.passes[k].gate.when, SIM_WHEN_CONTACT); // the floor's, with contact
    }
  EXPECT_EQ(sink.marks, (std::vector<PassCategory>{kContact, kIntegrate, kIntegrate, kHash, kCollide, kProject,
                                                   kProject, kProject, kFloor, kFloor, kProject, kTear}));
  EXPECT_EQ(marksPerSubstep(), sink.marks.size());
}

TEST(SubstepPasses, ATickCutShortRecordsThePassesUpToItsLast) {
  const SheetTopology topo = tenderSheet(6, 5);
  const SheetLayout sizes = layoutOf(topo);
  for (const ColorRange& range : topo.colors) ASSERT_GT(range.count, 0u);
  const SimPipelines pipes = fakePipelines();
  shaderio::SimUniforms u{};
  u.substeps = 1;
  u.iterations = 1;
  u.color_count = topo.colorCount();
  u.flags = SIM_FLAG_COLLISION;
  u.grab_index = SIM_NONE; // nothing holds the sheet: the limit shortens edges first
  u.limit.reach = 1.0f;
  u.hinge.count = topo.hingeCount();
  u.crease.yield_angle = 0.2f;
  ASSERT_GT(u.hinge.count, 0u);
  // The last kernel each stage records
  const auto lastOf = [](PassKind kind) -> std::string {
    switch (kind) {
    case PassKind::air:
      return "air";
    case PassKind::integrate:
      return "integrate";
    case PassKind::project: // a hinge colour's: project_hinge
      return "project";
    case PassKind::shorten:
      return "shorten";
    case PassKind::limit:
      return "limit";
    case PassKind::crease:
      return "crease";
    case PassKind::collide:
      return "repel";
    case PassKind::floor:
      return "floor";
    case PassKind::tear:
      return "tear_compact";
    case PassKind::contact: // without contact neither records anything
    case PassKind::settle:
    case PassKind::reset:
      break;
    }
    return "?";
  };
  for (uint32_t stop = 0; stop < passesPerTick(u); ++stop) {
    RecordingSink sink(pipes);
    uint32_t pass = 0;
    EXPECT_TRUE(recordSubstep(sink, pipes, topo, sizes, substepPlan(u, stop), 0, pass)) << stop;
    EXPECT_EQ(pass, stop + 1);
    const PassPoint at = passAt(u, stop);
    ASSERT_FALSE(sink.passes.empty());
    if (at.kind == PassKind::shorten) { // a colour without edges records nothing; every other one pass
      size_t shortens = 0, edge_colours = 0;
      for (const Recorded& r : sink.passes) shortens += r.kernel == "shorten";
      for (uint32_t c = 0; c <= at.color; ++c)
        edge_colours += constraintKind(topo.constraints[topo.colors[c].first]) == SIM_KIND_STRUCTURAL;
      EXPECT_GT(edge_colours, 0u);
      EXPECT_EQ(shortens, edge_colours) << describePass(at);
      if (constraintKind(topo.constraints[topo.colors[at.color].first]) != SIM_KIND_STRUCTURAL) continue;
    }
    const bool hinges = constraintKind(topo.constraints[topo.colors[at.color].first]) == SIM_KIND_HINGE;
    EXPECT_EQ(sink.passes.back().kernel, at.kind == PassKind::project && hinges ? "project_hinge" : lastOf(at.kind))
        << describePass(at);
    if (at.kind == PassKind::project) {
      size_t projects = 0;
      for (const Recorded& r : sink.passes) projects += r.kernel == "project" || r.kernel == "project_hinge";
      EXPECT_EQ(projects, at.color + 1) << describePass(at); // every colour of this sheet has constraints
    }
  }
}
