// tender: receipt paper physics. The interactive demo, and the headless commands `sim`, `render`, `diff`,
// `sweep`, `sweep-merge`, `devices` and `presets` (each in its own file).
#include <cstdio>

#include <CLI/CLI.hpp>

#include "commands.h"
#include "core/output.h"

namespace tender {

namespace {

void addCommon(CLI::App& app, CommonOptions& o, bool with_backend) {
  std::string names;
  const auto all = presetNames();
  for (size_t k = 0; k < all.size(); ++k) names += (k == 0 ? "" : k + 1 == all.size() ? " or " : ", ") + all[k];
  CLI::Option* preset = app.add_option("--preset", o.preset, names)->capture_default_str();
  app.add_option("--preset-file", o.preset_file, "a preset as JSON (see `tender presets --dump NAME`)")
      ->excludes(preset);
  app.add_option("--set", o.sets, "override a parameter: key=value (repeatable; see the key list below)");
  if (with_backend) app.add_option("--backend", o.backend, "cpu or gpu")->capture_default_str();
  app.add_option("--device", o.device, "Vulkan device index (see `tender devices`)");
  app.add_flag("--validation", o.validation, "enable VK_LAYER_KHRONOS_validation");
}

std::string keyList() {
  std::string s = "Parameter keys for --set:\n";
  for (auto& k : paramKeys()) {
    char line[160];
    std::snprintf(line, sizeof(line), "  %-20s %s\n", k.key.c_str(), k.help.c_str());
    s += line;
  }
  return s;
}

// Resolves the preset and the overrides; returns an error message.
std::optional<std::string> resolve(CommonOptions& o) {
  std::optional<SimParams> p;
  if (!o.preset_file.empty()) {
    SimParams loaded;
    if (auto err = loadPresetFile(o.preset_file, loaded)) return *err;
    p = loaded;
  } else {
    p = presetParams(o.preset);
  }
  if (!p) return unknownPreset(o.preset);
  for (auto& s : o.sets)
    if (auto err = applyOverride(*p, s)) return *err;
  if (o.backend != "cpu" && o.backend != "gpu") return "unknown backend '" + o.backend + "' (cpu or gpu)";
  if (auto err = validate(*p, o.backend)) return *err;
  o.params = *p;
  return std::nullopt;
}

/// The command line: every command's options, as CLI11 fills them.
struct CommandLine {
  CommonOptions common;
  DemoOptions demo;
  SimOptions sim;
  RenderOptions render;
  DiffOptions diff;
  SweepOptions sweep;
  SweepMergeOptions merge;
  std::string sim_ticks = "120", render_ticks = "0", frames_every, diff_ticks, dump_preset;
  CLI::Option* demo_backend = nullptr;
  CLI::Option* render_ticks_given = nullptr;
  CLI::App *sim_cmd = nullptr, *render_cmd = nullptr, *diff_cmd = nullptr, *sweep_cmd = nullptr, *merge_cmd = nullptr,
           *devices_cmd = nullptr, *presets_cmd = nullptr;
};

void addDemo(CLI::App& app, CommandLine& c) {
  addCommon(app, c.common, true);
  c.demo_backend = app.get_option("--backend");
  c.demo_backend->description("cpu or gpu (the demo: cpu when its Vulkan device is a CPU device, such as\n"
                              "lavapipe, which runs the simulation slower than the CPU backend; gpu otherwise)");
  DemoOptions& demo = c.demo;
  app.add_option("--record", demo.record, "write this session's input as an input script");
  app.add_option("--replay", demo.replay, "play an input script back");
  app.add_option("--quit-at", demo.quit_at, "end the session at this step (of --replay's or --record's clock)")
      ->check(CLI::Range(uint64_t(1), uint64_t(100000000)));
  app.add_option("--vsync", demo.vsync, "on or off")->transform(CLI::Transformer({{"on", "1"}, {"off", "0"}}));
  app.add_option("--ui-scale", demo.ui_scale, "HUD scale (default: the window's content scale)")
      ->check(finiteRange(0.25, 8.0));
  app.add_option("--width", demo.width, "window width")->check(CLI::Range(64u, 16384u));
  app.add_option("--height", demo.height, "window height")->check(CLI::Range(64u, 16384u));
}

void addSim(CLI::App& app, CommandLine& c) {
  CLI::App* cmd = c.sim_cmd = app.add_subcommand("sim", "run a preset headless and write stats and state");
  addCommon(*cmd, c.common, true);
  cmd->add_option("--ticks", c.sim_ticks, "ticks to run (decimal, at most 100000000)")->capture_default_str();
  cmd->add_option("--script", c.common.script, "input script to replay");
  cmd->add_option("--stats", c.sim.stats, "write stats JSON here");
  cmd->add_flag("--kernel-times", c.common.kernel_times,
                "GPU: time each kernel apart, gpu_ms_per_kernel in the stats (a timestamp after every dispatch "
                "of the per-colour passes, so the kernels do not overlap)");
  cmd->add_option("--out", c.sim.out, "write the final state here: FILE.ply, FILE.glb or FILE.gltf (glTF 2.0)");
  cmd->add_option("--frames-every", c.frames_every,
                  "a frame every K ticks: --out DIR/ writes frame_000000.glb..., --out FILE.glb one animation");
}

void addRender(CLI::App& app, CommandLine& c) {
  RenderOptions& render = c.render;
  CLI::App* cmd = c.render_cmd =
      app.add_subcommand("render", "render a preset offscreen to a PNG, or a video of the run");
  addCommon(*cmd, c.common, true);
  c.render_ticks_given =
      cmd->add_option("--ticks", c.render_ticks, "ticks to run before rendering (decimal)")->capture_default_str();
  cmd->add_option("--script", c.common.script, "input script to replay");
  CLI::Option* out = cmd->add_option("--out", render.out, "PNG to write")->capture_default_str();
  CLI::Option* video = cmd->add_option("--video", render.video,
                                       "write a video of the run instead (H.264 MP4, needs "
                                       "ffmpeg)")
                           ->excludes(out);
  cmd->add_option("--fps", render.fps, "video frames per second (at most 240)")->capture_default_str()->needs(video);
  cmd->add_option("--seconds", render.seconds, "video length (default: --ticks, or the script and 1 s, or 5 s)")
      ->excludes(c.render_ticks_given)
      ->needs(video);
  cmd->add_option("--width", render.width, "image width")->check(CLI::Range(16u, 16384u));
  cmd->add_option("--height", render.height, "image height")->check(CLI::Range(16u, 16384u));
}

void addDiff(CLI::App& app, CommandLine& c) {
  CLI::App* cmd = c.diff_cmd =
      app.add_subcommand("diff", "run the same input on two backends and find where their states first differ");
  addCommon(*cmd, c.common, false);
  cmd->add_option("--ticks", c.diff_ticks, "ticks to compare (decimal)")->required();
  cmd->add_option("--script", c.common.script, "input script to replay");
  cmd->add_option("--a", c.diff.a, "first backend: cpu, gpu, gpu:N (device N), gpu-percolor[:N]")->required();
  cmd->add_option("--b", c.diff.b, "second backend, as --a")->required();
  cmd->footer("Exit status: 0 identical, 1 the backends differ (the first tick, substep, pass and\n"
              "particle or constraint are printed), 2 bad input.");
}

void addSweep(CLI::App& app, CommandLine& c) {
  SweepOptions& sweep = c.sweep;
  CLI::App* cmd = c.sweep_cmd =
      app.add_subcommand("sweep", "run many sheets, each with its own values of some parameters, in batches");
  addCommon(*cmd, c.common, true);
  cmd->add_option("--vary", sweep.vary, "KEY=v1,v2,... or KEY=a:b:n (n values from a to b); repeat for a grid")
      ->required();
  cmd->add_option("--samples", sweep.samples, "draw N random sheets from the ranges KEY=a:b instead of a grid");
  cmd->add_option("--seed", sweep.seed, "seed of --samples (default 0)");
  cmd->add_option("--script", c.common.script, "input script every sheet replays");
  cmd->add_option("--ticks", sweep.ticks, "ticks every sheet runs (decimal)")->required();
  cmd->add_option("--batch", sweep.batch, "most sheets per batch (default: cpu 64, gpu 1024, less if memory is short)");
  cmd->add_option("--shard", sweep.shard, "i/n: run only the sheets whose index is i modulo n");
  cmd->add_option("--out", sweep.out, "folder of sheets.jsonl and sweep.json")->required();
  cmd->add_flag("--ply", sweep.ply, "also write each sheet's end state as DIR/sheet_NNNNNN.ply");
  cmd->footer("Grid order: the last --vary changes fastest. Each line of sheets.jsonl holds the sheet's index,\n"
              "its values and `tender sim --stats`'s fields; how its batch ran is under \"batch\".\n\n" +
              keyList());

  CLI::App* merge = c.merge_cmd =
      app.add_subcommand("sweep-merge", "join the shards of a sweep (tender sweep --shard) into one");
  merge->add_option("dirs", c.merge.dirs, "the shards' folders");
  merge->add_option("--out", c.merge.out, "folder of the whole sweep's sheets.jsonl and sweep.json")->required();
  merge->footer("The folders must hold shards of one sweep that together have every sheet exactly once;\n"
                "otherwise one line names what differs or the missing or doubled sheets (exit status 2).");
}

void addListings(CLI::App& app, CommandLine& c) {
  c.devices_cmd = app.add_subcommand("devices", "list the Vulkan devices");
  addCommon(*c.devices_cmd, c.common, false);
  c.presets_cmd = app.add_subcommand("presets", "list the presets, or print one as a --preset-file");
  c.presets_cmd->add_option("--dump", c.dump_preset, "print this preset as JSON, every key (a file for --preset-file)");
}

/// Checks what is left to check and runs the command the line names.
int runCommand(CommandLine& c) {
  if (*c.devices_cmd) return runDevices(c.common);
  if (*c.presets_cmd) return runPresets(c.dump_preset);
  if (*c.merge_cmd) return runSweepMerge(c.merge);
  if (*c.diff_cmd) c.common.backend = "cpu"; // each side is checked for its own backend
  if (auto err = resolve(c.common)) return fail(*err);
  if (auto err = parseWhole(c.sim_ticks, 0, kMaxTicks, c.sim.ticks)) return fail("--ticks: " + *err);
  if (!c.frames_every.empty())
    if (auto err = parseWhole(c.frames_every, 1, kMaxTicks, c.sim.frames_every)) return fail("--frames-every: " + *err);
  if (auto err = parseWhole(c.render_ticks, 0, kMaxTicks, c.render.ticks)) return fail("--ticks: " + *err);
  c.render.ticks_given = c.render_ticks_given->count() > 0;
  if (*c.diff_cmd)
    if (auto err = parseWhole(c.diff_ticks, 1, kMaxTicks, c.diff.ticks)) return fail("--ticks: " + *err);
  // A write beyond the file-size limit fails like any other write error (exit 2, no fragment).
  ignoreFileSizeSignal();
  if (*c.sim_cmd) return runSim(c.common, c.sim);
  if (*c.render_cmd) return runRender(c.common, c.render);
  if (*c.diff_cmd) return runDiff(c.common, c.diff);
  if (*c.sweep_cmd) return runSweep(c.common, c.sweep);
  c.common.backend_given = c.demo_backend->count() > 0;
  return runDemo(c.common, c.demo);
}

} // namespace
} // namespace tender

int main(int argc, char** argv) {
  using namespace tender;
  CLI::App app{"Tender: a sheet of receipt paper to grab, crumple, fold, toss and tear."};
  app.set_version_flag("--version", std::string(kProgramName) + " " + TENDER_VERSION);
  app.footer(keyList());
  app.require_subcommand(0, 1);
  CommandLine c;
  addDemo(app, c);
  addSim(app, c);
  addRender(app, c);
  addDiff(app, c);
  addSweep(app, c);
  addListings(app, c);
  if (const std::optional<int> status = parseArgs(app, argc, argv)) return *status;
  // Everything a command prints must reach standard output: a lost line is an error (exit 2).
  try {
    return finishOutput(runCommand(c));
  } catch (const std::bad_alloc&) {
    return fail("out of memory");
  } catch (const std::exception& e) { // a Vulkan error at run time
    return fail(e.what());
  }
}
