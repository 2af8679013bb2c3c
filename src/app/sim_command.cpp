// `tender sim`: run a preset headless, print a summary, write stats JSON and the sheet (PLY or
// glTF: the end state, a numbered sequence of frames, or one animated file).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "core/output.h"
#include "core/progress.h"
#include "core/simulation.h"
#include "core/stats.h"
#include "export/gltf.h"

namespace tender {
namespace {

/// Most frames of one animated file (its weights track grows with the square of the frames).
constexpr uint64_t kMaxAnimationFrames = 1000;
/// Most files of a numbered sequence.
constexpr uint64_t kMaxSequenceFrames = 100000;

/// What --out (with --frames-every) asks for.
struct MeshPlan {
  enum Kind { None, Ply, Gltf, Animation, Sequence } kind = None;
  bool binary = true;                ///< .glb (the sequence is always .glb)
  std::vector<std::string> frames;   ///< the sequence's files
  std::vector<uint64_t> frame_ticks; ///< the ticks the frames are taken at (animation, sequence)
};

/// How many frames are taken at 0, K, 2K, ... and the last tick.
uint64_t frameCount(uint64_t ticks, uint64_t every) { return ticks / every + 1 + (ticks % every != 0 ? 1 : 0); }

/// The ticks a frame is taken at: 0, K, 2K, ... and the last tick.
std::vector<uint64_t> frameTicks(uint64_t ticks, uint64_t every) {
  std::vector<uint64_t> t;
  for (uint64_t k = 0; k <= ticks; k += every) t.push_back(k);
  if (t.back() != ticks) t.push_back(ticks);
  return t;
}

std::optional<std::string> planMesh(const SimOptions& o, MeshPlan& plan) {
  if (o.out.empty()) {
    if (o.frames_every) return "--frames-every needs --out DIR/ or --out FILE.glb|FILE.gltf";
    return std::nullopt;
  }
  std::error_code ec;
  const bool folder = o.out.back() == '/' || std::filesystem::is_directory(o.out, ec);
  if (folder) {
    if (!o.frames_every)
      return "--out '" + o.out + "' is a folder: name a file, or add --frames-every K for a sequence";
    if (frameCount(o.ticks, o.frames_every) > kMaxSequenceFrames)
      return "--frames-every " + std::to_string(o.frames_every) + " over " + std::to_string(o.ticks) +
             " ticks makes more than " + std::to_string(kMaxSequenceFrames) + " files";
    plan.kind = MeshPlan::Sequence;
    plan.frame_ticks = frameTicks(o.ticks, o.frames_every);
    const std::string dir = o.out.back() == '/' ? o.out : o.out + "/";
    for (size_t k = 0; k < plan.frame_ticks.size(); ++k) {
      char name[32];
      std::snprintf(name, sizeof(name), "frame_%06zu.glb", k);
      plan.frames.push_back(dir + name);
    }
    return std::nullopt;
  }
  auto format = meshFormatFor(o.out);
  if (!format) return "--out '" + o.out + "': unknown extension (.ply, .glb or .gltf, or a folder DIR/)";
  if (*format == MeshFormat::Ply) {
    if (o.frames_every) return "--frames-every writes glTF: --out DIR/, FILE.glb or FILE.gltf, not PLY";
    plan.kind = MeshPlan::Ply;
    return std::nullopt;
  }
  plan.binary = *format == MeshFormat::Glb;
  if (!o.frames_every) {
    plan.kind = MeshPlan::Gltf;
    return std::nullopt;
  }
  if (frameCount(o.ticks, o.frames_every) > kMaxAnimationFrames)
    return "--frames-every " + std::to_string(o.frames_every) + " over " + std::to_string(o.ticks) +
           " ticks makes more than " + std::to_string(kMaxAnimationFrames) +
           " frames for one animated file (write a sequence: --out DIR/)";
  plan.kind = MeshPlan::Animation;
  plan.frame_ticks = frameTicks(o.ticks, o.frames_every);
  return std::nullopt;
}

/// Checks every output of the run (and that no input is one) before it starts.
std::optional<std::string> addSimOutputs(const CommonOptions& common, const SimOptions& o, const MeshPlan& plan,
                                         OutputSet& outputs) {
  if (auto err = outputs.addInput(common.script)) return err;
  if (auto err = outputs.addInput(common.preset_file)) return err;
  if (auto err = outputs.add(o.stats)) return err;
  if (plan.kind != MeshPlan::Sequence) return outputs.add(o.out);
  for (const std::string& path : plan.frames)
    if (auto err = outputs.add(path)) return err;
  return std::nullopt;
}

/// The run's summary on standard output.
void printSimRun(const CommonOptions& common, const SimOptions& o, Solver& solver, const SheetStats& st, double median,
                 double slowest, const std::string& hash) {
  std::printf("tender sim: preset %s, backend %s, %ux%u = %u particles, %llu ticks\n", common.params.preset.c_str(),
              solver.name().c_str(), common.params.cols, common.params.rows, st.particles,
              static_cast<unsigned long long>(o.ticks));
  std::printf("  constraints %u structural, %u shear, %u bend, %u tri-bend, %u hinge in %u colours; %u torn; %u "
              "triangles; %u creased\n",
              st.constraints[0], st.constraints[1], st.constraints[2], st.constraints[3], st.constraints[4], st.colors,
              st.torn, st.triangles, st.creased);
  std::printf("  bbox (%.3f %.3f %.3f) .. (%.3f %.3f %.3f), max stretch %.4f, NaN %u, intersecting pairs %lld\n",
              st.bbox_min.x, st.bbox_min.y, st.bbox_min.z, st.bbox_max.x, st.bbox_max.y, st.bbox_max.z, st.max_stretch,
              st.nan_count, static_cast<long long>(st.pairs));
  std::printf("  %.4f ms/tick (median, slowest %.4f), state hash %s\n", median, slowest, hash.c_str());
  std::fflush(stdout);
}

/// The scene of a glTF output: the receipt texture, rasterised before the run (a missing font
/// fails early).
MeshScene meshScene(const MeshPlan& plan, const SimParams& params) {
  MeshScene scene;
  if (plan.kind != MeshPlan::None && plan.kind != MeshPlan::Ply) {
    scene.uv = buildSheet(params).uv;
    scene.texture_png = receiptPng(params.preset);
  }
  return scene;
}

/// Stages the stats and the end state's mesh (or the animation of `frames`) once the run is done.
std::optional<std::string> stageSimOutputs(const SimOptions& o, const MeshPlan& plan, const SimState& state,
                                           const nlohmann::json& j, const MeshScene& scene,
                                           std::vector<MeshFrame>& frames, OutputSet& outputs) {
  if (!o.stats.empty())
    if (auto err = outputs.stage(o.stats, j.dump(2) + "\n")) return err;
  if (plan.kind == MeshPlan::Ply) return outputs.stage(o.out, [&](std::FILE* f) { return writePly(f, state); });
  if (plan.kind != MeshPlan::Gltf && plan.kind != MeshPlan::Animation) return std::nullopt;
  if (plan.kind == MeshPlan::Gltf) frames = {meshFrame(state, 0.0)};
  std::string error;
  auto bytes = encodeGltf(scene, frames, plan.binary, error);
  if (!bytes) return error;
  return outputs.stage(o.out, *bytes);
}

} // namespace

int runSim(const CommonOptions& common, const SimOptions& o) {
  catchInterrupts(); // Ctrl-C or SIGTERM: the run stops between ticks, writes nothing and says so
  // Every output is checked before the run, and written only when the run has succeeded.
  MeshPlan plan;
  if (auto err = planMesh(o, plan)) return fail(*err);
  OutputSet outputs;
  if (auto err = addSimOutputs(common, o, plan, outputs)) return fail(*err);
  MeshScene scene = meshScene(plan, common.params);
  std::string error;
  auto script = scriptFor(common.script, common.params, common.backend, error);
  if (!script) return fail(error);
  Backend backend;
  if (auto err = createBackend(common.backendOptions(), backend)) return fail(*err);
  Solver& solver = *backend.solver;
  Simulation sim(common.params, solver);
  sim.setScript(*script);

  // Frames (--frames-every): the sequence's files are staged as they are taken, the animation's
  // frames kept for the one file written at the end.
  std::vector<MeshFrame> frames;
  size_t next_frame = 0;
  auto takeFrame = [&](uint64_t tick) -> std::optional<std::string> {
    if (next_frame >= plan.frame_ticks.size() || plan.frame_ticks[next_frame] != tick) return std::nullopt;
    solver.computeNormals();
    SimState s;
    solver.readback(s);
    MeshFrame f = meshFrame(s, double(tick) / double(common.params.tick_hz));
    if (plan.kind == MeshPlan::Animation) {
      frames.push_back(std::move(f));
    } else {
      std::string err;
      scene.uv = sim.topology().uv; // the sheet as it is now (a script's set may have rebuilt it)
      auto bytes = encodeGltf(scene, {f}, true, err);
      if (!bytes) return err;
      if (auto e = outputs.stage(plan.frames[next_frame], *bytes)) return e;
    }
    ++next_frame;
    return std::nullopt;
  };

  std::vector<double> ms;
  ms.reserve(size_t(std::min<uint64_t>(o.ticks, 1u << 20)));
  if (auto err = takeFrame(0)) return fail(*err);
  // A bar on a terminal once the run has taken a second; nothing otherwise.
  Progress progress("tender sim", "tick", o.ticks, 1.0);
  for (uint64_t t = 0; t < o.ticks; ++t) {
    if (interrupted()) {
      progress.clear();
      return fail(interruptMessage() + "; nothing written");
    }
    auto t0 = std::chrono::steady_clock::now();
    bool ran = sim.tick();
    if (ran) solver.finish();
    auto t1 = std::chrono::steady_clock::now();
    if (ran) ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    if (auto err = takeFrame(t + 1)) {
      progress.clear();
      return fail(*err);
    }
    progress.update(t + 1);
  }
  progress.clear();
  solver.computeNormals();
  SimState state;
  solver.readback(state);
  SheetStats st = computeStats(state, sim.lastSubstepDt());
  judgeIntersections(st, state);
  double median = 0.0, slowest = 0.0;
  nlohmann::json j = runStatsJson(st, solver, {common.params.preset, o.ticks, sim.physicsTicks(), std::move(ms)},
                                  backend.gpu != nullptr, &median, &slowest);

  printSimRun(common, o, solver, st, median, slowest, j["state_hash"].get<std::string>());

  scene.uv = sim.topology().uv;
  if (auto err = stageSimOutputs(o, plan, state, j, scene, frames, outputs)) return fail(*err);
  if (interrupted()) return fail(interruptMessage() + "; nothing written");
  if (auto err = outputs.commit()) return fail(*err);
  return 0;
}

} // namespace tender
