// Parity of what makes paper paper on every GPU path with the CPU reference: tearing with contact,
// creases, the hand's crumple, the stretch limit and penetration-free contact (its lists, its settle).
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <set>

#include "core/intersections.h"
#include "core/stats.h"
#include "cpu/cpu_solver.h"
#include "gpu/gpu_solver.h"
#include "gpu_test_env.h"
#include "parity.h"

using namespace tender;
using namespace tender::test;

TEST_F(Parity, TheTenderPresetWithContactTearsTheSameOnTheGpu) {
  // The preset as it ships: wind, the particle repulsion and contact, a corner yanked until it
  // tears (the hand's pace runs more substeps while the grab drags)
  SimParams p = clothWithContact({"cols=16", "rows=24"});
  ASSERT_GT(p.contact_factor, 0.0f);
  for (bool fused : {true, false}) {
    auto [cpu, gpu] = runBoth(ctx(), p, "0 grab particle 383\n1 move 3 -3 3\n", 16, fused);
    EXPECT_GT(tornIds(cpu).size(), 0u);
    EXPECT_TRUE(sameState(cpu, gpu));
    expectSameTopology(cpu, gpu);
  }
}

TEST_F(Parity, CreasesAreTheSameOnEveryPath) {
  // A sheet laid flat, its far edge lifted over and pressed down: the hinges crease, and their rest
  // angles, yields and multipliers hold the same bits on the CPU and both GPU paths.
  SimParams p = paperSheet({"cols=12", "rows=16", "tilt=90", "pins=none", "top_y=-9.9", "crease_yield=5"});
  std::string text = "0 grab particle 186\n";
  for (int t = 1; t <= 40; ++t) {
    const float f = float(t) / 40.0f;
    text += std::to_string(t) + " move 0.075 " + std::to_string(-9.9f + 2.0f * std::sin(3.14159265f * f)) + " " +
            std::to_string(-2.25f + 2.2f * f) + "\n";
  }
  for (bool fused : {true, false}) {
    auto [cpu, gpu] = runBoth(ctx(), p, text.c_str(), 60, fused);
    uint32_t creased = 0;
    for (const glm::vec4& h : cpu.hinges) creased += h.x != 0.0f ? 1u : 0u;
    std::printf("crease, %s: %u of %zu hinges creased\n", fused ? "fused tick" : "per-colour passes", creased,
                cpu.hinges.size());
    EXPECT_GT(creased, 10u);
    EXPECT_TRUE(sameState(cpu, gpu));
    expectSameTopology(cpu, gpu);
  }
}

namespace {

/// The middle of a sheet lying on the floor lifted (at the hand's pace: 32 substeps), the hand half
/// closed and closed around it, then moved (32 again) and let go, the sheet tossed at the drag's
/// speed and in contact throughout: the CPU's bits in the fused tick or on the per-colour passes.
void expectTheHandCrumplesTheSame(gpu::VulkanContext& ctx, bool fused) {
  const SimParams p = crumpleSheet({"cols=12", "rows=16", "tilt=90", "pins=none", "top_y=-9.9"});
  const char* text =
      "0 grab particle 102\n1 move 0 -8.8 -1.2\n3 squeeze 0.5\n6 squeeze 1\n9 move 1 -8 -1\n13 release\n";
  auto [cpu, gpu] = runBoth(ctx, p, text, 16, fused);
  EXPECT_TRUE(sameState(cpu, gpu));
  expectSameTopology(cpu, gpu);
}

} // namespace

TEST_F(Parity, TheHandCrumplesTheSameInTheFusedTick) { expectTheHandCrumplesTheSame(ctx(), true); }
TEST_F(Parity, TheHandCrumplesTheSameOnThePerColourPasses) { expectTheHandCrumplesTheSame(ctx(), false); }

TEST_F(Parity, ACrumpledSheetOnTheDevicesOwnPathHasTheCpuBits) {
  // The hand closing on the `crumple` sheet at 32 x 48 with twelve settle sweeps, on the path the
  // device takes by itself. The fused tick with the settle in its workgroup ran past lavapipe's
  // loop count in tick 3 and parted from the CPU (FusedShape::contact): a CPU device runs a sheet
  // with contact on the per-colour passes, a GPU in the fused tick.
  const SimParams p = crumpleSheet(
      {"cols=32", "rows=48", "tilt=90", "pins=none", "wind=off", "floor_y=-3", "top_y=-2.925", "contact_settle=12"});
  const char* text = "0 grab particle 1220\n1 move 0.075 -2.79167 -4.5\n1 squeeze 0.0666667\n"
                     "2 move 0.075 -2.65833 -4.5\n2 squeeze 0.133333\n3 move 0.075 -2.525 -4.5\n3 squeeze 0.2\n";
  auto [cpu, gpu] = runBoth(ctx(), p, text, 4, true, gpu::FusedShape{});
  EXPECT_TRUE(sameState(cpu, gpu));
}

TEST_F(Parity, TheStretchLimitIsTheSameOnEveryPath) {
  // Sheets lying on the floor, a corner dragged away fast: the limit holds the edges it reaches
  // within 1 % while those at the grab tear. Wider than long and longer than wide (the rings walk
  // the shorter side), and with the grab let go (the rings then run from the middle).
  for (const char* size : {"cols=16", "cols=9"}) {
    const SimParams p = paperSheet({size, "rows=12", "tilt=90", "pins=none", "top_y=-9.9"});
    const uint32_t corner = (p.rows - 1) * p.cols;
    const std::string text =
        "0 grab particle " + std::to_string(corner) + "\n1 move -3 -8 -2\n12 move -5 -7 4\n" + "20 release\n";
    for (bool fused : {true, false}) {
      // one run, read at tick 16 (the grab still dragging) and at tick 30 (let go)
      gpu::GpuSolver gpu_solver(ctx());
      CpuSolver cpu_solver;
      gpu_solver.setFusedPath(fused);
      Simulation a(p, cpu_solver), b(p, gpu_solver);
      a.setScript(script(text.c_str()));
      b.setScript(script(text.c_str()));
      int done = 0;
      for (int ticks : {16, 30}) {
        const SimState cpu = run(a, ticks - done), gpu = run(b, ticks - done);
        done = ticks;
        const SheetStats st = computeStats(cpu, p.substepDt());
        std::printf("stretch limit %s, %s, %d ticks: most stretch %.4f, %zu torn\n", size,
                    fused ? "fused tick" : "per-colour passes", ticks, double(st.max_stretch), tornIds(cpu).size());
        EXPECT_LE(st.max_stretch, 1.02f);
        EXPECT_TRUE(sameState(cpu, gpu)) << size << (fused ? " fused tick" : " per-colour passes") << " " << ticks;
        expectSameTopology(cpu, gpu);
      }
    }
  }
  // Sheets hanging from their pins, one iteration and a tight limit: the rings run from every pin
  // (limitRootSet), each particle around the one nearest it, and place particles every substep
  for (const char* pins : {"pins=corners", "pins=top3"}) {
    const SimParams p = paperSheet({"cols=16", "rows=24", pins, "iterations=1", "stretch_limit=1.001"});
    for (bool fused : {true, false}) {
      auto [cpu, gpu] = runBoth(ctx(), p, "", 20, fused);
      const SheetStats st = computeStats(cpu, p.substepDt());
      std::printf("stretch limit %s, %s: most stretch %.5f\n", pins, fused ? "fused tick" : "per-colour passes",
                  double(st.max_stretch));
      EXPECT_LE(st.max_stretch, 1.0011f) << pins;
      EXPECT_TRUE(sameState(cpu, gpu)) << pins << (fused ? " fused tick" : " per-colour passes");
    }
  }
  // A sheet whose rings take two dispatches on a CPU device (limitRingsPerDispatch; a GPU's
  // larger workgroup walks them in one), dragged far off by a corner: a strip 8 wide, about the
  // fewest particles whose rings from the grab run on for dozens past a dispatch's, pulled whole
  // (no tearing, no pins) so that the last rings move too
  const SimParams big = paperSheet({"cols=8", "rows=2400", "tilt=90", "pins=none", "tear_factor=0"});
  const uint32_t grab = (big.rows - 1) * big.cols;
  const glm::uvec4 roots =
      shaderio::limitRootSet(glm::uvec4(SIM_NONE, SIM_NONE, SIM_NONE, 0u), grab, big.cols, big.rows);
  if (gpu::limitWorkgroup(ctx()) == SIM_WG_LIMIT) {
    ASSERT_GT(shaderio::limitLastRing(roots, big.cols, big.rows),
              shaderio::limitRingsPerDispatch(big.cols, big.rows, SIM_WG_LIMIT) + 32u);
  }
  const std::string far_off = "0 grab particle " + std::to_string(grab) + "\n1 move -20 -4 -400\n";
  auto [cpu, gpu] = runBoth(ctx(), big, far_off.c_str(), 2, false);
  EXPECT_LT(cpu.pos[0].z, -10.0f); // the far end, in the last ring, pulled along
  EXPECT_TRUE(sameState(cpu, gpu));
}

TEST_F(Parity, AStripHeldUnderAFoldIsPulledFreeOnEveryPath) {
  // Contact.AStripHeldUnderAFoldIsPulledFree's scene (a yanked 8 x 12 `tender` sheet whose strip by
  // its pin ends under a fold): the steps' excess passed on to the other side of their pairs
  // (contact_pass) frees it with the same bits on the CPU and both GPU paths, to tick 60, while it
  // is being freed (stretched 9.08 there without the passing on, 1.80 with; the CPU test sees it
  // freed by tick 120)
  const SimParams p = clothWithContact({"cols=8", "rows=12", "tear_factor=50"});
  for (bool fused : {true, false}) {
    auto [cpu, gpu] = runBoth(ctx(), p, "0 grab particle 95\n1 move 6 -5 6\n30 release\n", 60, fused);
    const float stretch = computeStats(cpu, p.substepDt()).max_stretch;
    std::printf("hooked strip, %s: max stretch %.4f at tick 60\n", fused ? "fused tick" : "per-colour passes",
                double(stretch));
    EXPECT_LT(stretch, 2.0f);
    EXPECT_TRUE(sameState(cpu, gpu)) << (fused ? "fused tick" : "per-colour passes");
  }
}

namespace {

// The hanging sheet's bottom middle dragged up and back through the sheet, contact turned on at
// tick 29 and the sheet let go at 32.
std::string forcedThroughScript(const SimParams& p) {
  const uint32_t bottom = (p.rows - 1) * p.cols + p.cols / 2;
  const float height = float(p.rows - 1) * p.spacing;
  glm::vec3 b;
  {
    CpuSolver probe;
    Simulation sim(p, probe);
    b = glm::vec3(run(sim, 0).pos[bottom]);
  }
  std::string text = "0 grab particle " + std::to_string(bottom) + "\n";
  char line[160];
  auto path = [&](int t0, glm::vec3 from, glm::vec3 to, int ticks) {
    for (int t = 1; t <= ticks; ++t) {
      const glm::vec3 q = from + (to - from) * (float(t) / float(ticks));
      std::snprintf(line, sizeof(line), "%d move %.6f %.6f %.6f\n", t0 + t, q.x, q.y, q.z);
      text += line;
    }
  };
  const glm::vec3 front = b + glm::vec3(0.0f, 0.05f * height, 0.8f), high = b + glm::vec3(0.0f, 0.7f * height, 0.8f);
  path(0, b, front, 8);
  path(8, front, high, 12);
  path(20, high, high - glm::vec3(0.0f, 0.0f, 1.6f), 8);
  text += "29 set contact_factor 0.5\n32 release\n";
  return text;
}

} // namespace

TEST_F(Parity, ContactIsTheSameOnTheGpu) {
  // Penetration-free contact, in the fused tick and on the per-colour passes. The
  // hanging sheet's bottom middle dragged up and back through the sheet with the particle repulsion
  // alone, then contact turned on (the GPU sizes its buffers then) and the sheet let go: the
  // particles of the crossing triangles go free, and the bounds, pushes and free particles hold the
  // CPU's bits on the way out, as does the count of particles in contact.
  const SimParams p = paperSheet({"cols=16", "rows=24"});
  const std::string text = forcedThroughScript(p);
  CpuSolver cpu;
  Simulation a(p, cpu);
  a.setScript(script(text.c_str()));
  const SimState forced = run(a, 29);
  const uint32_t crossed = intersectingPairs(forced.pos, forced.triangles, forced.triangle_count).pairs;
  const SimState cpu_end = run(a, 45);
  const uint32_t left = intersectingPairs(cpu_end.pos, cpu_end.triangles, cpu_end.triangle_count).pairs;
  std::printf("contact: %u pairs crossing when it starts, %u 45 ticks later; %lld particles in contact\n", crossed,
              left, static_cast<long long>(cpu.contacts()));
  EXPECT_GT(crossed, 0u);
  EXPECT_LT(left, crossed);
  EXPECT_GT(cpu.contacts(), 0);
  for (uint32_t capacity : {SIM_CONTACT_LIST_CAPACITY, 1u}) {
    // On the per-colour passes (the fused tick takes the yank below); with lists of one pair, the
    // queries with more search the grid every substep, with the same bits. The forcing through,
    // contact off, runs the fused tick (the paths take turns bitwise below), the per-colour passes
    // from the tick that turns contact on and sizes its buffers.
    gpu::GpuSolver gpu(ctx());
    gpu.setContactListCapacity(capacity);
    Simulation g(p, gpu);
    g.setScript(script(text.c_str()));
    run(g, 29);
    EXPECT_TRUE(gpu.usesFusedPath(g.lastUniforms())) << capacity << " pairs a list";
    gpu.setFusedPath(false);
    const SimState gpu_end = run(g, 45);
    EXPECT_EQ(cpu.contacts(), gpu.contacts()) << capacity << " pairs a list";
    EXPECT_TRUE(sameState(cpu_end, gpu_end)) << capacity << " pairs a list";
    std::printf("%u pairs a list: the lists were built %u times in %u substeps\n", capacity, gpu.contactListBuilds(),
                45 * p.substeps);
  }
  {
    // The fused tick (contact in its workgroup) and the per-colour passes by turns, each going on
    // from the lists the other built: the passes walk the queries their own last build named only
    // while those lists stand
    gpu::GpuSolver gpu(ctx(), gpu::FusedShape{0, 0, 0.0f, 1});
    Simulation g(p, gpu);
    g.setScript(script(text.c_str()));
    run(g, 29);
    EXPECT_TRUE(gpu.usesFusedPath(g.lastUniforms()));
    for (int t = 0; t < 44; ++t) {
      gpu.setFusedPath(t % 2 == 0);
      g.tick();
    }
    gpu.setFusedPath(false);
    EXPECT_TRUE(sameState(cpu_end, run(g, 1))) << "the fused tick and the per-colour passes by turns";
  }
}

TEST_F(Parity, ATornSheetWithContactIsTheSameOnTheGpu) {
  // A yank that tears the sheet with contact on from the start: torn triangles stop colliding at
  // once. Both ways: the fused tick with contact's bodies in its workgroup (a GPU's), the per-colour
  // passes (a CPU device's).
  const SimParams yank = clothWithContact({"cols=12", "rows=16", "wind=off"});
  for (bool fused : {true, false}) {
    const char* way = fused ? "fused tick" : "per-colour passes";
    gpu::GpuSolver gpu(ctx(), kContactInTheWorkgroup);
    gpu.setFusedPath(fused);
    Simulation g(yank, gpu);
    g.tick();
    EXPECT_EQ(gpu.usesFusedPath(g.lastUniforms()), fused) << way;
    // The fused tick's one dispatch a tick (a CPU device's: one a substep)
    if (fused) {
      EXPECT_LE(gpu.dispatchesPerTick(), yank.substeps) << way;
    }
    auto [torn_cpu, torn_gpu] = runBoth(ctx(), yank, "0 grab particle 191\n1 move 6 -4 5\n", 10, fused);
    EXPECT_GT(tornIds(torn_cpu).size(), 0u) << way;
    EXPECT_TRUE(sameState(torn_cpu, torn_gpu)) << way;
    expectSameTopology(torn_cpu, torn_gpu);
  }
  // Unless told, a CPU device runs a sheet with contact on the per-colour passes (lavapipe's loop
  // count: FusedShape::contact), a GPU in the fused tick
  gpu::GpuSolver plain(ctx());
  Simulation g(yank, plain);
  g.tick();
  EXPECT_EQ(plain.usesFusedPath(g.lastUniforms()), ctx().properties().deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU);
}

TEST_F(Parity, AFallingSheetWithContactIsTheSameOnTheGpu) {
  // The receipt falling without air with contact on: the frame of its steps (contactFrame) is taken
  // out before the bound on every path, so it falls freely, with the CPU's bits; its substeps
  // changed mid-fall, the frame takes the first substep's rescale (contactFrameScale). A small sheet
  // at three times gravity and 4 substeps outruns three bounds a substep within 12 ticks.
  const SimParams p =
      receiptWithContact({"cols=6", "rows=16", "substeps=4", "gravity=30", "air=off", "tilt=90", "floor_y=-100"});
  for (bool fused : {true, false}) {
    auto [cpu, gpu] = runBoth(ctx(), p, "6 set substeps 12\n9 set substeps 6\n", 12, fused);
    EXPECT_GT(computeStats(gpu, p.substepDt()).max_speed,
              3.0f * SIM_CONTACT_FRACTION * p.contactRadius() * p.tick_hz * float(p.substeps));
    EXPECT_TRUE(sameState(cpu, gpu)) << (fused ? "fused tick" : "per-colour passes");
  }
}

TEST_F(Parity, ContactListsStandWhileTheGpuPathsTakeTurns) {
  // A sheet lying on the floor gathered into a ball by the closed hand and held there: its layers,
  // held apart by contact alone, press on each other and come nearly to rest, so the lists of pairs
  // stand for many substeps. The
  // fused tick (contact in its workgroup) and the per-colour passes then take turns a tick each: the
  // passes take over lists the fused tick built (which name no queries: they are built again) and
  // the fused tick goes on from the passes' lists; the bits stay the CPU's, and the lists are not
  // built every substep.
  const SimParams p = crumpleSheet({"cols=12", "rows=16", "tilt=90", "pins=none", "top_y=-9.9", "collision=off"});
  const std::string text = "0 grab particle 102\n1 move 0 -8.8 -1.2\n4 squeeze 0.5\n12 squeeze 1\n";
  constexpr int kSettle = 60, kTurns = 30;
  CpuSolver cpu;
  Simulation a(p, cpu);
  a.setScript(script(text.c_str()));
  const SimState cpu_end = run(a, kSettle + kTurns);
  EXPECT_GT(cpu.contacts(), 0);
  EXPECT_EQ(intersectingPairs(cpu_end.pos, cpu_end.triangles, cpu_end.triangle_count).pairs, 0u);
  gpu::GpuSolver gpu(ctx(), gpu::FusedShape{0, 0, 0.0f, 1});
  Simulation g(p, gpu);
  g.setScript(script(text.c_str()));
  run(g, kSettle);
  const uint32_t before = gpu.contactListBuilds();
  for (int t = 0; t < kTurns; ++t) {
    gpu.setFusedPath(t % 2 == 0);
    g.tick();
  }
  const uint32_t builds = gpu.contactListBuilds() - before;
  std::printf("resting layers, the paths by turns: %lld particles in contact, the lists built %u times in %u "
              "substeps\n",
              static_cast<long long>(cpu.contacts()), builds, kTurns * p.substeps);
  EXPECT_EQ(cpu.contacts(), gpu.contacts());
  EXPECT_LT(builds, uint32_t(kTurns) * p.substeps / 4);
  EXPECT_TRUE(sameState(cpu_end, run(g, 0))) << "the fused tick and the per-colour passes by turns";
}

TEST_F(Parity, TheSettleIsTheSameOnTheGpu) {
  // The hand's fist closing on a small sheet with contact on and the settle's sweeps (the
  // contact_settle key): the edges the contact holds past the stretch limit are shortened within the
  // steps' bounds with the CPU's bits on the per-colour passes and in the fused tick (whose
  // workgroup runs the settle after the contact's bodies there, a GPU's way). The sweeps do their
  // work here: the sheet ends elsewhere and less stretched than without them.
  const SimParams p =
      crumpleSheet({"cols=12", "rows=16", "tilt=90", "pins=none", "top_y=-9.9", "collision=off", "contact_settle=4"});
  const std::string text = "0 grab particle 102\n1 move 0 -8.8 -1.2\n4 squeeze 0.5\n12 squeeze 1\n";
  constexpr int kTicks = 14;
  auto cpuRun = [&](const SimParams& q) {
    CpuSolver cpu;
    Simulation a(q, cpu);
    a.setScript(script(text.c_str()));
    float most = 0.0f;
    SimState s;
    for (int t = 0; t < kTicks; ++t) {
      s = run(a, 1);
      most = std::max(most, computeStats(s, q.substepDt()).max_stretch);
    }
    return std::make_pair(s, most);
  };
  SimParams none = p;
  none.contact_settle = 0;
  const auto [cpu_end, settled] = cpuRun(p);
  const auto [cut_end, cut] = cpuRun(none);
  std::printf("the fist with contact: most stretch %.4f with the cut alone, %.4f with 4 settle sweeps\n", double(cut),
              double(settled));
  EXPECT_LT(settled, cut);
  EXPECT_FALSE(sameState(cpu_end, cut_end));
  EXPECT_EQ(intersectingPairs(cpu_end.pos, cpu_end.triangles, cpu_end.triangle_count).pairs, 0u);
  struct Way {
    const char* name;
    bool fused;
    int contact; // FusedShape::contact
  };
  for (const Way way : {Way{"per-colour passes", false, 1}, Way{"fused tick", true, 1}}) {
    gpu::GpuSolver gpu(ctx(), gpu::FusedShape{0, 0, 0.0f, way.contact});
    gpu.setFusedPath(way.fused);
    Simulation g(p, gpu);
    g.setScript(script(text.c_str()));
    const SimState gpu_end = run(g, kTicks);
    EXPECT_EQ(gpu.usesFusedPath(g.lastUniforms()), way.fused) << way.name;
    EXPECT_TRUE(sameState(cpu_end, gpu_end)) << way.name;
    if (way.fused) continue;
    // The per-colour passes dispatch the settle's passes indirectly: in the last substep the
    // half-spaces' passes ran (slot 0) while an edge was over the limit, a sweep only after the one
    // before it, and none past the key's; a sheet hanging at rest runs none of them.
    auto armed = [&](gpu::GpuSolver& solver) {
      std::vector<glm::uvec4> args(SIM_SHEET_ARGS);
      solver.context().download(solver.buffer(SIM_BIND_HASH_ARGS), args.data(), 16ull * args.size());
      std::vector<bool> slots;
      for (uint32_t k = 0; k < SIM_CONTACT_SETTLE_SLOTS; ++k) slots.push_back(args[SIM_CONTACT_SETTLE_ARGS + k].x > 0);
      return slots;
    };
    const std::vector<bool> fist = armed(gpu);
    EXPECT_TRUE(fist[0] && fist[1]) << "the fist's last substep starts the settle";
    for (uint32_t k = 1; k < SIM_CONTACT_SETTLE_SLOTS; ++k)
      EXPECT_TRUE(!fist[k] || (fist[k - 1] && k <= p.contact_settle)) << "sweep " << k - 1;
    const SimParams hanging = crumpleSheet({"cols=12", "rows=16", "collision=off", "contact_settle=4"});
    gpu::GpuSolver still(ctx(), gpu::FusedShape{0, 0, 0.0f, way.contact});
    still.setFusedPath(false);
    Simulation h(hanging, still);
    run(h, 2);
    for (bool slot : armed(still)) EXPECT_FALSE(slot) << "a hanging sheet's settle";
  }
}
