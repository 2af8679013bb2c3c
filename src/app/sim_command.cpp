// `tender sim`: run a preset headless, print a summary, write stats JSON and a PLY.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>

#include "commands.h"
#include "core/simulation.h"
#include "core/stats.h"
#include "cpu/cpu_solver.h"

#ifdef TENDER_HAS_GPU
#include "gpu/gpu_solver.h"
#endif

namespace tender {

std::unique_ptr<Solver> createSolver(const CommonOptions& o, int& status) {
  status = 0;
  if (o.backend == "cpu") return std::make_unique<CpuSolver>(CpuOptions{o.params.threads});
#ifdef TENDER_HAS_GPU
  gpu::GpuOptions g;
  g.device = o.device;
  g.validation = o.validation;
  std::string error;
  auto solver = gpu::createGpuSolver(g, error);
  if (!solver) status = fail(error + " (try --backend cpu)");
  return solver;
#else
  status = fail("this build has no Vulkan backend (try --backend cpu)");
  return nullptr;
#endif
}

int runSim(const CommonOptions& common, const SimOptions& o) {
  InputScript script;
  if (!common.script.empty()) {
    std::string error;
    auto s = loadScript(common.script, error);
    if (!s) return fail(error);
    if (auto err = checkScript(*s, common.params.particleCount())) return fail(common.script + ": " + *err);
    script = *s;
  }
  int status = 0;
  auto solver = createSolver(common, status);
  if (!solver) return status;
  Simulation sim(common.params, *solver);
  sim.setScript(script);

  std::vector<double> ms;
  ms.reserve(o.ticks);
  SimState probe;
  for (uint64_t t = 0; t < o.ticks; ++t) {
    auto t0 = std::chrono::steady_clock::now();
    bool ran = sim.tick();
    if (ran && solver->name() == "gpu") solver->particlePosition(0); // wait for the tick to finish
    auto t1 = std::chrono::steady_clock::now();
    if (ran) ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
  }
  solver->computeNormals();
  SimState state;
  solver->readback(state);
  SheetStats st = computeStats(state, common.params.substepDt());
  double median = 0.0;
  if (!ms.empty()) {
    std::nth_element(ms.begin(), ms.begin() + ms.size() / 2, ms.end());
    median = ms[ms.size() / 2];
  }

  nlohmann::json j = statsJson(st);
  j["preset"] = common.params.preset;
  j["backend"] = solver->name();
  j["ticks"] = o.ticks;
  j["physics_ticks"] = sim.physicsTicks();
  j["ms_per_tick"] = median;
  j["dispatches_per_tick"] = solver->dispatchesPerTick();
  nlohmann::json passes = nlohmann::json::object();
  for (auto& [name, t] : solver->passTimes().ms) passes[name] = t;
  if (solver->name() == "gpu") j["gpu_ms_per_pass"] = passes;

  std::printf("tender sim: preset %s, backend %s, %ux%u = %u particles, %llu ticks\n", common.params.preset.c_str(),
              solver->name().c_str(), common.params.cols, common.params.rows, st.particles,
              static_cast<unsigned long long>(o.ticks));
  std::printf("  constraints %u structural, %u shear, %u bend, %u tri-bend in %u colours; %u torn; %u triangles\n",
              st.constraints[0], st.constraints[1], st.constraints[2], st.constraints[3], st.colors, st.torn,
              st.triangles);
  std::printf("  bbox (%.3f %.3f %.3f) .. (%.3f %.3f %.3f), max stretch %.4f, NaN %u\n", st.bbox_min.x, st.bbox_min.y,
              st.bbox_min.z, st.bbox_max.x, st.bbox_max.y, st.bbox_max.z, st.max_stretch, st.nan_count);
  std::printf("  %.4f ms/tick (median), state hash %s\n", median, j["state_hash"].get<std::string>().c_str());

  if (!o.stats.empty()) {
    std::ofstream f(o.stats);
    if (!(f << j.dump(2) << '\n')) return fail("cannot write stats '" + o.stats + "'");
  }
  if (!o.out.empty() && !writePly(o.out, state)) return fail("cannot write '" + o.out + "'");
  return 0;
}

} // namespace tender
