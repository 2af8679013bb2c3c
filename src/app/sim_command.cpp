// `tender sim`: run a preset headless, print a summary, write stats JSON and a PLY.
#include <algorithm>
#include <chrono>
#include <cstdio>

#include "commands.h"
#include "core/output.h"
#include "core/simulation.h"
#include "core/stats.h"

namespace tender {

int runSim(const CommonOptions& common, const SimOptions& o) {
  // Every output is checked before the run, and written only when the run has succeeded.
  OutputSet outputs;
  for (const std::string& path : {o.stats, o.out})
    if (auto err = outputs.add(path)) return fail(*err);
  std::string error;
  auto script = scriptFor(common.script, common.params, error);
  if (!script) return fail(error);
  Backend backend;
  if (auto err = createBackend(common.backendOptions(), backend)) return fail(*err);
  Solver& solver = *backend.solver;
  Simulation sim(common.params, solver);
  sim.setScript(*script);

  std::vector<double> ms;
  ms.reserve(size_t(std::min<uint64_t>(o.ticks, 1u << 20)));
  for (uint64_t t = 0; t < o.ticks; ++t) {
    auto t0 = std::chrono::steady_clock::now();
    bool ran = sim.tick();
    if (ran) solver.finish();
    auto t1 = std::chrono::steady_clock::now();
    if (ran) ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
  }
  solver.computeNormals();
  SimState state;
  solver.readback(state);
  SheetStats st = computeStats(state, common.params.substepDt());
  double median = 0.0, slowest = 0.0;
  if (!ms.empty()) {
    slowest = *std::max_element(ms.begin(), ms.end());
    std::nth_element(ms.begin(), ms.begin() + ms.size() / 2, ms.end());
    median = ms[ms.size() / 2];
  }

  nlohmann::json j = statsJson(st);
  j["preset"] = common.params.preset;
  j["backend"] = solver.name();
  j["ticks"] = o.ticks;
  j["physics_ticks"] = sim.physicsTicks();
  j["ms_per_tick"] = median;
  j["ms_slowest_tick"] = slowest;
  j["dispatches_per_tick"] = solver.dispatchesPerTick();
  const Arithmetic arith = solver.arithmetic();
  j["arithmetic"] = {{"rounding", arith.rounding}, {"denormals", arith.denormals}, {"corrected", arith.corrected}};
  j["inexact_math_emulated"] = arith.inexact_math_emulated;
  nlohmann::json passes = nlohmann::json::object();
  for (auto& [name, t] : solver.passTimes().ms) passes[name] = t;
  if (backend.gpu) j["gpu_ms_per_pass"] = passes;

  std::printf("tender sim: preset %s, backend %s, %ux%u = %u particles, %llu ticks\n", common.params.preset.c_str(),
              solver.name().c_str(), common.params.cols, common.params.rows, st.particles,
              static_cast<unsigned long long>(o.ticks));
  std::printf("  constraints %u structural, %u shear, %u bend, %u tri-bend in %u colours; %u torn; %u triangles\n",
              st.constraints[0], st.constraints[1], st.constraints[2], st.constraints[3], st.colors, st.torn,
              st.triangles);
  std::printf("  bbox (%.3f %.3f %.3f) .. (%.3f %.3f %.3f), max stretch %.4f, NaN %u\n", st.bbox_min.x, st.bbox_min.y,
              st.bbox_min.z, st.bbox_max.x, st.bbox_max.y, st.bbox_max.z, st.max_stretch, st.nan_count);
  std::printf("  %.4f ms/tick (median, slowest %.4f), state hash %s\n", median, slowest,
              j["state_hash"].get<std::string>().c_str());
  std::fflush(stdout);

  if (!o.stats.empty())
    if (auto err = outputs.stage(o.stats, j.dump(2) + "\n")) return fail(*err);
  if (!o.out.empty())
    if (auto err = outputs.stage(o.out, [&](std::FILE* f) { return writePly(f, state); })) return fail(*err);
  if (auto err = outputs.commit()) return fail(*err);
  return 0;
}

} // namespace tender
