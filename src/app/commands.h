#pragma once
/// The subcommands of `tender`, each in its own file; main.cpp parses the command line.
#include <memory>
#include <string>
#include <vector>

#include "backend/backend.h"
#include "cli/cli.h"
#include "core/params.h"
#include "core/script.h"
#include "core/solver.h"

namespace tender {

namespace render {
struct HeadlessOptions;
} // namespace render

/// Exit status of tender-demo started by `tender` (kLaunchedVariable set) when no window can be
/// opened: `tender` then renders a picture instead, as with no display at all.
constexpr int kExitNoWindow = 3;
/// Set in tender-demo's environment when `tender` starts it.
constexpr const char* kLaunchedVariable = "TENDER_LAUNCHED";

/// Options every program shares.
struct CommonOptions {
  std::string preset = "tender";
  std::string preset_file;       ///< a preset as JSON (--preset-file), instead of --preset
  std::vector<std::string> sets; ///< key=value overrides
  std::string backend = "gpu";   ///< cpu or gpu
  bool backend_given = false;    ///< --backend was given (the demo's own choice otherwise: runDemo)
  int device = -1;               ///< Vulkan device index, -1 = best
  bool validation = false;       ///< VK_LAYER_KHRONOS_validation
  std::string script;            ///< input script to replay
  bool kernel_times = false;     ///< `sim --kernel-times`: the GPU's time by kernel in the stats
  SimParams params;              ///< resolved preset + overrides

  /// The backend these options ask for (threads from the parameters).
  BackendOptions backendOptions() const;
};

struct SimOptions {
  uint64_t ticks = 120;
  std::string stats, out;    ///< out: .ply, .glb, .gltf (by extension), or a folder with frames_every
  uint64_t frames_every = 0; ///< --frames-every K: a frame every K ticks (glTF); 0 = the end state only
};

/// Largest --ticks of `tender sim` and `tender render`.
constexpr uint64_t kMaxTicks = 100000000;

struct DiffOptions {
  uint64_t ticks = 0;
  std::string a, b; ///< backends: cpu, gpu, gpu:N, gpu-percolor, gpu-percolor:N
};

/// `tender sweep`, as given on the command line (runSweep parses and checks it).
struct SweepOptions {
  std::vector<std::string> vary;                  ///< KEY=v1,v2,... or KEY=a:b:n; KEY=a:b with --samples
  std::string ticks, samples, seed, batch, shard; ///< empty: not given
  std::string out;                                ///< the folder of sheets.jsonl and sweep.json
  bool ply = false;                               ///< also DIR/sheet_NNNNNN.ply per sheet
};

/// `tender sweep-merge`: the shards' folders and the folder of the whole sweep.
struct SweepMergeOptions {
  std::vector<std::string> dirs;
  std::string out;
};

struct RenderOptions {
  uint64_t ticks = 0;
  std::string out = "tender.png";
  uint32_t width = 1280, height = 720;
  // A video instead of a picture (--video): every frame, encoded by ffmpeg.
  std::string video;      ///< the MP4 to write; empty: a PNG
  std::string fps = "60"; ///< frames per second (decimal, at most 3 places)
  std::string seconds;    ///< length (decimal); empty: from --ticks
  bool ticks_given = false;
};

struct DemoOptions {
  std::string record, replay;
  uint64_t quit_at = 0; ///< the script clock's step at which the session ends (0: never)
  bool vsync = true;
  float ui_scale = 0.0f; ///< 0 = the window's content scale
  uint32_t width = 1280, height = 720;
};

/// The input script of `path` checked against the sheet of `params` (an empty path: no events);
/// nullopt and `error` on failure.
std::optional<InputScript> scriptFor(const std::string& path, const SimParams& params, const std::string& backend,
                                     std::string& error);

int runSim(const CommonOptions& common, const SimOptions& o);
int runDevices(const CommonOptions& common);
/// `tender presets`: the names of the presets, or (`name` given) that preset as JSON.
int runPresets(const std::string& name);
/// `tender diff`: 0 when the two backends give bitwise the same states every tick, 1 when they
/// part (where is printed), 2 on bad input.
int runDiff(const CommonOptions& common, const DiffOptions& o);
/// `tender sweep`: the sheets of a grid or a sample of parameter values (of one shard), in batches;
/// writes DIR/sheets.jsonl (one line of stats per sheet) and DIR/sweep.json (its definition).
int runSweep(const CommonOptions& common, const SweepOptions& o);
/// `tender sweep-merge`: joins the shards of one sweep into the whole sweep's files.
int runSweepMerge(const SweepMergeOptions& o);
int runRender(const CommonOptions& common, const RenderOptions& o);
/// The offscreen picture `tender render` (and its --video) asks for: the sheet, backend, device,
/// size and input script of these options (the ticks are the caller's).
void headlessOptionsFor(const CommonOptions& common, const RenderOptions& o, const InputScript& script,
                        render::HeadlessOptions& out);
/// `tender render --video`: every frame of the run piped to ffmpeg (H.264 MP4).
int runVideo(const CommonOptions& common, const RenderOptions& o);
/// The program's main job: `tender` launches tender-demo (or, without a renderer, runs the simulation
/// headless); tender-demo opens its window.
int runDemo(const CommonOptions& common, const DemoOptions& o);
/// The name --version prints: defined beside runDemo, by the file that makes each program what it is.
extern const char* const kProgramName;

} // namespace tender
