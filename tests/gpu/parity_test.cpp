// Parity of the GPU solver with the CPU reference, and determinism of the GPU solver.
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

TEST_F(Parity, HashBucketsMatchTheCpu) {
  // Run a while, then rebuild the hash from exactly the read-back positions on both sides: a
  // tick with dt = 0, damping = 0 and no iterations moves nothing before the hash is built.
  SimParams p = paperSheet({"cols=24", "rows=30", "wind=on"});
  gpu::GpuSolver gpu(ctx());
  Simulation sim(p, gpu);
  SimState s = run(sim, 30);
  // A hash in every substep: no candidate lists
  gpu.setCandidateLists(false);
  shaderio::SimUniforms u = sim.makeUniforms();
  u.substeps = 1;
  u.iterations = 0;
  u.dt = 0.0f;
  u.damping = 0.0f;
  u.tear_factor = 0.0f;
  u.grab_index = SIM_NONE;
  gpu.tick(u);
  std::vector<uint32_t> gpu_start, gpu_particles;
  gpu.readHash(gpu_start, gpu_particles);
  SimState after_gpu;
  gpu.readback(after_gpu);

  CpuSolver cpu;
  cpu.upload(sim.topology());
  for (uint32_t i = 0; i < s.pos.size(); ++i) cpu.positions()[i] = s.pos[i];
  cpu.previous() = s.prev;
  cpu.hingeStates() = s.hinges;
  cpu.tick(u);
  EXPECT_EQ(cpu.cellStart(), gpu_start);
  EXPECT_EQ(cpu.cellParticles(), gpu_particles);
  // The collision gather sums in the same order: the states agree bitwise.
  SimState after_cpu;
  cpu.readback(after_cpu);
  EXPECT_TRUE(sameState(after_cpu, after_gpu));
}

TEST_F(Parity, HugeHashTableUsesThreeScanLevelsAndTallGrids) {
  // 2^23 buckets: the scan needs three levels (8192 and 8 block sums) and adding the block sums
  // back takes 131072 workgroups, more than one grid row (the grid spills into Y).
  SimParams p = cloth({"cols=24", "rows=30", "wind=on"});
  SheetTopology topo = buildSheet(p);
  topo.hash_size = 1u << 23;
  CpuSolver scratch_solver;
  Simulation sim(p, scratch_solver); // only for the uniforms of a tick
  gpu::GpuSolver gpu(ctx());
  gpu.setCandidateLists(false); // a hash in every substep
  CpuOptions no_lists;
  no_lists.candidate_lists = false;
  CpuSolver cpu(no_lists);
  gpu.upload(topo);
  cpu.upload(topo);
  shaderio::SimUniforms u = sim.makeUniforms();
  u.hash_mask = topo.hash_size - 1;
  gpu.tick(u); // a tick builds the hash in each of its substeps
  cpu.tick(u);
  std::vector<uint32_t> gpu_start, gpu_particles;
  gpu.readHash(gpu_start, gpu_particles);
  ASSERT_EQ(cpu.cellStart().size(), gpu_start.size());
  size_t mismatches = 0;
  for (size_t h = 0; h < gpu_start.size(); ++h)
    if (cpu.cellStart()[h] != gpu_start[h] && mismatches++ < 5)
      ADD_FAILURE() << "bucket " << h << ": cpu start " << cpu.cellStart()[h] << ", gpu " << gpu_start[h];
  EXPECT_EQ(mismatches, 0u);
  EXPECT_EQ(cpu.cellParticles(), gpu_particles);
  SimState a, b;
  cpu.readback(a);
  gpu.readback(b);
  EXPECT_TRUE(sameState(a, b));
}

TEST_F(Parity, NoCollisionNoTearFor240Ticks) {
  // Time is the subject, not size: a 16 x 24 sheet dragged by its last corner and let go
  SimParams p = cloth({"cols=16", "rows=24", "collision=off", "tear_factor=0"});
  for (bool fused : {true, false}) {
    auto [cpu, gpu] = runBoth(ctx(), p, "0 grab particle 383\n2 move 2 -1 2\n120 release\n", 240, fused);
    EXPECT_TRUE(sameState(cpu, gpu));
  }
}

TEST_F(Parity, FullPhysicsTender30Ticks) {
  // The seeds' cloth (the preset with contact: TheTenderPresetWithContactTearsTheSameOnTheGpu)
  SimParams p = cloth();
  for (bool fused : {true, false}) {
    auto [cpu, gpu] = runBoth(ctx(), p, "0 grab particle 1535\n1 move 1 -1 3\n", 30, fused);
    EXPECT_TRUE(sameState(cpu, gpu));
    expectSameTopology(cpu, gpu);
  }
}

TEST_F(Parity, FullPhysicsCrumple30Ticks) {
  // The crumple preset with wind, contact and the hand's pace, on the per-colour passes its own
  // sheet runs on a device with 32 KiB of shared memory (over fusedCapacity); at 16 x 24, a sixth of
  // its particles (the fused tick's crumple: TheHandCrumplesTheSameInTheFusedTick)
  SimParams p = crumpleSheet({"cols=16", "rows=24", "wind=on"});
  auto [cpu, gpu] = runBoth(ctx(), p, "0 grab particle 383\n1 move 4 -6 4\n15 release\n", 30, false);
  EXPECT_TRUE(sameState(cpu, gpu));
  expectSameTopology(cpu, gpu);
}

TEST_F(Parity, PaperInTheAir) {
  // The air on each triangle (its own pass, or the first step of the fused tick) through a throw
  // that tears, its substeps changed in flight (the first substep after a change rescales the
  // velocity, SimUniforms::verlet): the same bits on both GPU paths and the CPU. Without contact,
  // which holds the throw's edges within the limit (AFallingSheetWithContactIsTheSameOnTheGpu changes
  // the substeps with it).
  SimParams p = receiptSheet({"tear_factor=1.6"});
  for (bool fused : {true, false}) {
    auto [cpu, gpu] = runBoth(
        ctx(), p, "0 grab particle 1036\n1 move 0.2 0.6 0.1\n8 release\n12 set substeps 12\n18 set substeps 6\n", 24,
        fused);
    std::printf("paper, 24 ticks, %s: %zu torn\n", fused ? "fused tick" : "per-colour passes", tornIds(cpu).size());
    EXPECT_GT(tornIds(cpu).size(), 0u);
    EXPECT_TRUE(sameState(cpu, gpu));
    expectSameTopology(cpu, gpu);
  }
}

TEST_F(Parity, ScriptedYankTearsTheSameConstraints) {
  // Grab the bottom-right corner and pull it far away fast.
  SimParams p = cloth({"wind=off"}); // the seeds' cloth
  auto [cpu, gpu] = runBoth(ctx(), p, "0 grab particle 1535\n1 move 7 -4 6\n", 12);
  ASSERT_GT(tornIds(cpu).size(), 0u);
  std::printf("yank: %zu torn on the CPU, %zu on the GPU; %u / %u triangles\n", tornIds(cpu).size(),
              tornIds(gpu).size(), cpu.triangle_count, gpu.triangle_count);
  expectSameTopology(cpu, gpu);
}

TEST_F(Parity, SameGpuRunTwiceIsBitwiseIdentical) {
  SimParams p = crumpleSheet({"cols=16", "rows=20", "wind=on"});
  const char* text = "0 grab particle 319\n1 move 5 -6 5\n15 release\n";
  auto once = [&] {
    gpu::GpuSolver gpu(ctx());
    Simulation sim(p, gpu);
    sim.setScript(script(text));
    return run(sim, 20);
  };
  SimState a = once(), b = once();
  EXPECT_EQ(hashPositions(a.pos), hashPositions(b.pos));
  EXPECT_EQ(0, std::memcmp(a.pos.data(), b.pos.data(), a.pos.size() * sizeof(glm::vec4)));
  EXPECT_EQ(a.torn, b.torn);
  EXPECT_EQ(a.triangles, b.triangles);
}

TEST_F(Parity, DegenerateSheetsWithEveryRule) {
  // 1 x N, N x 1, 1 x 1 and 2 x 2 sheets with every rule that walks the grid (on the CPU alone:
  // Degenerate.SheetsOneParticleWideOrLongTearHangAndCrumple): hinges and creases (crumple), the
  // stretch limit, contact, the hand's squeeze and a yank that tears; the same bits on both GPU
  // paths and the CPU.
  for (const auto& [cols, rows] : {std::pair{1, 10}, std::pair{10, 1}, std::pair{1, 1}, std::pair{2, 2}}) {
    for (const char* name : {"tender", "crumple"}) {
      const SimParams p =
          preset(name, {("cols=" + std::to_string(cols)).c_str(), ("rows=" + std::to_string(rows)).c_str(),
                        "stretch_limit=1.01", "contact_factor=0.5", "wind=off"});
      const std::string text = "0 grab particle " + std::to_string(cols * rows - 1) +
                               "\n1 move 0 0 0\n2 squeeze 1\n6 move 6 -4 5\n10 release\n";
      for (bool fused : {true, false}) {
        auto [cpu, gpu] = runBoth(ctx(), p, text.c_str(), 12, fused);
        std::printf("%dx%d %s, 12 ticks, %s: %zu torn\n", cols, rows, name, fused ? "fused" : "per-colour passes",
                    tornIds(cpu).size());
        EXPECT_TRUE(sameState(cpu, gpu)) << cols << "x" << rows << " " << name << (fused ? " fused" : " per-colour");
        expectSameTopology(cpu, gpu);
      }
    }
  }
}

TEST_F(Parity, AwkwardSizes) {
  // 7 x 11 = 77 particles: not a multiple of any workgroup size (64, 256) nor of the subgroup (8);
  // 1 x 2 the smallest sheet with a constraint (those one particle wide or long, with every rule:
  // DegenerateSheetsWithEveryRule).
  const std::pair<const char*, const char*> sizes[] = {
      {"cols=1", "rows=2"}, {"cols=7", "rows=11"}, {"cols=37", "rows=53"}};
  for (auto [c, r] : sizes) {
    SimParams p = cloth({c, r, "wind=on"});
    const uint32_t last = p.cols * p.rows - 1;
    std::string text = "0 grab particle " + std::to_string(last) + "\n1 move 3 -3 3\n";
    for (bool fused : {true, false}) {
      auto [cpu, gpu] = runBoth(ctx(), p, text.c_str(), 20, fused);
      std::printf("%s %s, 20 ticks, %s: %zu torn\n", c, r, fused ? "fused" : "per-colour passes", tornIds(cpu).size());
      EXPECT_TRUE(sameState(cpu, gpu)) << c << " " << r;
      expectSameTopology(cpu, gpu);
    }
  }
}

TEST_F(Parity, SyncValidationCatchesAMissingBarrier) {
  // The validation the GPU tests rely on is live: two writes to one buffer without a barrier.
  ASSERT_TRUE(ctx().validationEnabled());
  gpu::Buffer b = ctx().createDeviceBuffer(256, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  const uint32_t before = ctx().validationMessages();
  std::fprintf(stderr, "(a synchronization hazard is expected below)\n");
  ctx().submitOnce([&](VkCommandBuffer cmd) {
    vkCmdFillBuffer(cmd, b.buffer, 0, 256, 1u);
    vkCmdFillBuffer(cmd, b.buffer, 0, 256, 2u);
  });
  ctx().destroyBuffer(b);
  EXPECT_GT(ctx().validationMessages(), before);
  messages_ = ctx().validationMessages(); // the expected hazard does not fail the test
}

TEST_F(Parity, FusedSmallSheetPathMatchesSeparatePasses) {
  // The fused substep (one workgroup, shared memory) against the per-colour passes and the CPU.
  SimParams p = cloth({"wind=on"});
  const char* text = "0 grab particle 1535\n1 move 6 -5 6\n25 release\n";
  auto runGpu = [&](bool fused) {
    gpu::GpuSolver gpu(ctx());
    gpu.setFusedPath(fused);
    Simulation sim(p, gpu);
    EXPECT_EQ(gpu.usesFusedPath(), fused);
    sim.setScript(script(text));
    SimState s = run(sim, 40);
    std::printf("fused %d: %u dispatches per tick\n", int(fused), gpu.dispatchesPerTick());
    return s;
  };
  SimState fused = runGpu(true), separate = runGpu(false);
  CpuSolver cpu;
  Simulation sim(p, cpu);
  sim.setScript(script(text));
  SimState ref = run(sim, 40);
  EXPECT_TRUE(sameState(fused, separate));
  EXPECT_TRUE(sameState(ref, fused));
  expectSameTopology(ref, fused);
  expectSameTopology(separate, fused);
}

TEST_F(Parity, FusedTickInTheShapesOfBothKindsOfDevice) {
  // A CPU device (lavapipe) runs the fused tick as SIM_WG_FUSED_CPU invocations, one dispatch per
  // substep, and only with hash cells of at most SIM_FUSED_CPU_MAX_CELL_SPACINGS spacings; a GPU
  // runs the whole tick in one dispatch, any cell (kGpuLikeWorkgroup invocations). Both compute what
  // the CPU computes: a yank that tears, and buckets longer than the collision gather's window
  // (cells 10 spacings wide, which lavapipe leaves to the per-colour passes).
  struct Case {
    SimParams params;
    const char* script;
    bool fused_on_cpu_device;
  };
  const Case cases[] = {
      {cloth({"cols=16", "rows=24", "wind=on"}), "0 grab particle 383\n1 move 6 -5 6\n12 release\n", true},
      // just under the CPU device's cell limit (0.72): the densest buckets it fuses
      {cloth({"cols=16", "rows=24", "cell_size=0.7", "wind=on"}), "0 grab particle 383\n1 move 6 -5 6\n12 release\n",
       true},
      {cloth({"cols=24", "rows=30", "cell_size=1.8", "wind=on"}), "0 grab particle 719\n1 move 2 3 1\n", false},
      // the air pass first in every substep (without contact: its work in the workgroup, a whole
      // tick in one dispatch, runs past lavapipe's loop count, bench/README.md "Fused small sheets")
      {receiptSheet({"tear_factor=1.6"}), "0 grab particle 1036\n1 move 0.2 0.6 0.1\n8 release\n", true}};
  const gpu::FusedShape gpu_shape{kGpuLikeWorkgroup, SIM_MAX_SUBSTEPS, -1.0f, 1};
  const gpu::FusedShape cpu_shape{SIM_WG_FUSED_CPU, SIM_FUSED_SUBSTEPS_CPU, SIM_FUSED_CPU_MAX_CELL_SPACINGS, -1};
  for (const Case& c : cases) {
    const SimParams& p = c.params;
    CpuSolver cpu;
    Simulation cpu_sim(p, cpu);
    cpu_sim.setScript(script(c.script));
    const SimState ref = run(cpu_sim, 20);
    const uint32_t torn = tornCount(ref);
    EXPECT_GT(torn, 0u);
    for (bool gpu_like : {true, false}) {
      gpu::GpuSolver gpu(ctx(), gpu_like ? gpu_shape : cpu_shape);
      Simulation gpu_sim(p, gpu);
      const bool fused = gpu.usesFusedPath(gpu_sim.makeUniforms());
      ASSERT_EQ(fused, gpu_like || c.fused_on_cpu_device);
      if (!fused) continue; // the per-colour passes of that sheet: BucketsLongerThanTheGatherWindow
      gpu_sim.setScript(script(c.script));
      SimState got = run(gpu_sim, 20);
      const uint32_t dispatches = gpu.dispatchesPerTick();
      EXPECT_EQ(dispatches, gpu_like ? 1u : p.substeps);
      std::printf("%s shape, %ux%u, cell %.2f, %u dispatches/tick, 20 ticks: torn %u\n",
                  gpu_like ? "GPU" : "CPU-device", p.cols, p.rows, p.cell_size, dispatches, torn);
      EXPECT_TRUE(sameState(ref, got));
      expectSameTopology(ref, got);
    }
  }
}

TEST_F(Parity, FusedTickOfAnyWorkgroupSize) {
  // The fused tick's loops stride by its workgroup, whatever its size (tender-bench
  // --fused-workgroup): from a few SIMD groups (a substep a dispatch: each invocation's loops run
  // long, and lavapipe caps a dispatch's loop iterations) to SIM_WG_FUSED_MAX (the whole tick in
  // one dispatch), the CPU's bits through a yank that tears.
  const SimParams p = cloth({"wind=on"});
  const char* text = "0 grab particle 1535\n1 move 6 -5 6\n12 release\n";
  CpuSolver cpu;
  Simulation cpu_sim(p, cpu);
  cpu_sim.setScript(script(text));
  const SimState ref = run(cpu_sim, 16);
  EXPECT_GT(tornCount(ref), 0u);
  for (auto [workgroup, substeps] :
       {std::pair{32u, 1u}, std::pair{uint32_t(SIM_WG_FUSED_MAX), uint32_t(SIM_MAX_SUBSTEPS)}}) {
    gpu::GpuSolver gpu(ctx(), gpu::FusedShape{workgroup, substeps, -1.0f, 1});
    Simulation sim(p, gpu);
    ASSERT_TRUE(gpu.usesFusedPath(sim.makeUniforms()));
    EXPECT_EQ(gpu.fusedWorkgroup(), workgroup);
    sim.setScript(script(text));
    const SimState got = run(sim, 16);
    EXPECT_EQ(gpu.dispatchesPerTick(), (p.substeps + substeps - 1) / substeps) << workgroup;
    EXPECT_TRUE(sameState(ref, got)) << workgroup << " invocations";
    expectSameTopology(ref, got);
  }
}

TEST_F(Parity, BucketsLongerThanTheGatherWindow) {
  // Cells 10 spacings wide: a bucket holds far more particles than the collision gather's
  // 32-slot window, so buckets are read in several windows. The fused tick runs with any cell
  // here, one substep per dispatch of kGpuLikeWorkgroup invocations (well within lavapipe's loop count).
  SimParams p = cloth({"cols=24", "rows=30", "cell_size=1.8", "wind=on"});
  for (bool fused : {true, false}) {
    auto [cpu, gpu] = runBoth(ctx(), p, "0 grab particle 719\n1 move 2 3 1\n", 20, fused,
                              gpu::FusedShape{kGpuLikeWorkgroup, 1, -1.0f});
    EXPECT_TRUE(sameState(cpu, gpu));
    expectSameTopology(cpu, gpu);
  }
}

TEST_F(Parity, FarConnectedParticlesNeverRepel) {
  // Connect every particle of a strip to its mirror image across the middle row, far outside the
  // 5 x 5 grid stencil of the GPU's adjacency masks, then fold the strip in half so that the
  // mirrors meet: both solvers skip exactly those pairs (the GPU through the adjacency list).
  SimParams p = cloth({"cols=6", "rows=40", "wind=off", "tear_factor=0"});
  const char* text = "0 grab particle 237\n1 move 0.45 3 0.3\n";
  SheetTopology topo = buildSheet(p);
  std::vector<std::vector<uint32_t>> adj(topo.particleCount());
  for (uint32_t i = 0; i < adj.size(); ++i) {
    adj[i].assign(topo.adj_list.begin() + topo.adj_offsets[i], topo.adj_list.begin() + topo.adj_offsets[i + 1]);
    const uint32_t mirror = (p.rows - 1 - i / p.cols) * p.cols + i % p.cols;
    if (mirror != i && std::find(adj[i].begin(), adj[i].end(), mirror) == adj[i].end()) adj[i].push_back(mirror);
    std::sort(adj[i].begin(), adj[i].end());
  }
  topo.adj_list.clear();
  for (uint32_t i = 0; i < adj.size(); ++i) {
    topo.adj_offsets[i] = uint32_t(topo.adj_list.size());
    topo.adj_list.insert(topo.adj_list.end(), adj[i].begin(), adj[i].end());
  }
  topo.adj_offsets[adj.size()] = uint32_t(topo.adj_list.size());
  // Runs the folding script on a solver, with the far connections or with the sheet's own.
  auto fold = [&](Solver& solver, bool far) {
    Simulation sim(p, solver);
    if (far) solver.upload(topo);
    sim.setScript(script(text));
    return run(sim, 60);
  };
  CpuSolver plain_cpu, cpu;
  const SimState plain = fold(plain_cpu, false), ref = fold(cpu, true);
  // The mirrors do meet: connecting them changes the motion.
  EXPECT_NE(hashPositions(plain.pos), hashPositions(ref.pos));
  for (bool fused : {true, false}) {
    gpu::GpuSolver gpu(ctx());
    gpu.setFusedPath(fused);
    const SimState s = fold(gpu, true);
    EXPECT_TRUE(sameState(ref, s));
  }
}

namespace {

/// The fused tick's candidate-list state (Counters::candidate_state): x usable, y substeps since built, z
/// substeps to wait before the next build.
glm::uvec4 candidateState(gpu::GpuSolver& gpu) {
  shaderio::Counters c{};
  gpu.context().download(gpu.buffer(SIM_BIND_COUNTERS), &c, sizeof(c));
  return c.candidate_state;
}

} // namespace

TEST_F(Parity, CandidateListsHoldEveryCloseUnconnectedPair) {
  // A sheet hanging in the wind moves little between substeps, so both GPU paths gather their
  // collisions from the candidate lists most of the time. Whenever they are usable, each list
  // holds exactly the particles not connected to its particle within radius + skin of where they
  // were when the lists were built, in ascending order; and the run matches the CPU's. With a
  // radius of 1.6 spacings (skin 0.8) the lists are not empty: the particles one column and two
  // rows away (or two columns, one row) are unconnected and within 2.4 spacings.
  for (bool fused : {true, false})
    for (const char* factor : {"collision_factor=1.2", "collision_factor=1.6"})
      checkCandidateLists(cloth({"cols=16", "rows=24", "wind=on", factor}), fused,
                          std::strcmp(factor, "collision_factor=1.6") == 0);
}

void Parity::checkCandidateLists(const SimParams& p, bool fused, bool expect_entries) {
  gpu::GpuSolver gpu(ctx());
  gpu.setFusedPath(fused);
  Simulation sim(p, gpu);
  ASSERT_EQ(gpu.usesFusedPath(sim.makeUniforms()), fused);
  ASSERT_TRUE(gpu.usesCandidateLists());
  CpuSolver cpu;
  Simulation ref(p, cpu);
  const SheetTopology& topo = sim.topology();
  const uint32_t n = topo.particleCount();
  const shaderio::SimUniforms u = sim.makeUniforms();
  // The search radius and the membership test as the shaders compute them (exact division, no
  // contraction): every pair is in the lists or not by the same bits, with no band for rounding.
  const float r = u.collision_radius;
  const float search = r + shaderio::candidateSkin(r, u.inv_cell), search2 = search * search;
  uint32_t search_bits;
  std::memcpy(&search_bits, &search, 4);
  int whole_ticks_on_lists = 0, checked = 0;
  size_t entries = 0;
  const int ticks = 46; // four checks
  for (int t = 0; t < ticks; ++t) {
    run(sim, 1);
    run(ref, 1);
    const glm::uvec4 state = candidateState(gpu);
    if (state.x == 1u && state.y >= p.substeps) ++whole_ticks_on_lists;
    if (state.x != 1u || t % 15 != 0) continue;
    ++checked;
    EXPECT_EQ(state.w, search_bits) << "the lists were built with another search radius";
    std::vector<uint32_t> lists(size_t(SIM_CANDIDATE_STRIDE) * n);
    std::vector<glm::vec4> base(n);
    gpu.context().download(gpu.buffer(SIM_BIND_CANDIDATES), lists.data(), 4ull * lists.size());
    gpu.context().download(gpu.buffer(SIM_BIND_CANDIDATE_BASE), base.data(), 16ull * n);
    size_t bad = 0;
    for (uint32_t i = 0; i < n; ++i) {
      const uint32_t* rec = &lists[size_t(SIM_CANDIDATE_STRIDE) * i];
      ASSERT_LE(rec[0], SIM_CANDIDATE_CAPACITY);
      entries += rec[0];
      std::set<uint32_t> got(rec + 1, rec + 1 + rec[0]);
      EXPECT_TRUE(std::is_sorted(rec + 1, rec + 1 + rec[0]));
      for (uint32_t j = 0; j < n; ++j) {
        if (j == i || topo.adjacent(i, j)) {
          bad += got.count(j);
          continue;
        }
        const glm::vec3 d = glm::vec3(base[i]) - glm::vec3(base[j]);
        if (shaderio::dot3(d, d) < search2)
          bad += got.count(j) ? 0 : 1;
        else
          bad += got.count(j);
      }
    }
    EXPECT_EQ(bad, 0u) << "tick " << t;
  }
  SimState a, b;
  cpu.readback(a);
  gpu.readback(b);
  std::printf("%s, radius %.2f, %d ticks, %d of them wholly on candidate lists, %d list checks (%zu entries)\n",
              fused ? "fused" : "per-colour passes", r, ticks, whole_ticks_on_lists, checked, entries);
  EXPECT_GT(whole_ticks_on_lists, ticks / 2);
  if (expect_entries) {
    EXPECT_GT(entries, size_t(n));
  }
  EXPECT_GT(checked, 2);
  EXPECT_TRUE(sameState(a, b));
}

TEST_F(Parity, OverflowingCandidateListsFallBackToTheHash) {
  // A collision radius of 2.5 spacings reaches far past the connected neighbours: a particle has
  // more unconnected candidates than a list holds. Both GPU paths then wait SIM_CANDIDATE_WAIT
  // substeps before trying again, gathering from the hash meanwhile, and match the CPU.
  SimParams p = cloth({"cols=16", "rows=20", "collision_factor=2.5", "cell_size=0.9", "wind=on"});
  for (bool fused : {true, false}) {
    gpu::GpuSolver gpu(ctx(), gpu::FusedShape{kGpuLikeWorkgroup, 1, -1.0f});
    gpu.setFusedPath(fused);
    Simulation sim(p, gpu);
    ASSERT_EQ(gpu.usesFusedPath(sim.makeUniforms()), fused);
    CpuSolver cpu;
    Simulation ref(p, cpu);
    int waiting = 0;
    const int ticks = 20;
    for (int t = 0; t < ticks; ++t) {
      run(sim, 1);
      run(ref, 1);
      const glm::uvec4 state = candidateState(gpu);
      if (state.x == 0u && state.z > 0u) ++waiting;
    }
    SimState a, b;
    cpu.readback(a);
    gpu.readback(b);
    std::printf("%s, radius 2.5 spacings, %d ticks, %d ending in a wait after an overflow\n",
                fused ? "fused" : "per-colour passes", ticks, waiting);
    EXPECT_GT(waiting, 0);
    EXPECT_TRUE(sameState(a, b));
  }
}
