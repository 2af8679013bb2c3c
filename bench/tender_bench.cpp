// tender-bench: scaling benchmark of the solvers. For each sheet size and backend it runs the full
// physics (every substep, iteration, collision and tear check of the preset) and reports ms per
// tick (median, p95), particle-substeps per second, dispatches per tick, memory, the bytes a tick
// must move (bench/traffic.h) and the bandwidth that achieves against the machine's measured copy
// bandwidth and, on the GPU, the time and bandwidth of each pass and what one empty dispatch and
// its barrier cost on the device (bench/dispatch_cost.h). Bench sizes keep the sheet's physical
// size: spacing and hash cell scale with the grid (see bench/README.md).
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "backend/backend.h"
#include "bench_cases.h"
#include "cli/cli.h"
#include "core/output.h"
#include "report.h"

#ifdef TENDER_HAS_GPU
#include "dispatch_cost.h"
#include "gpu/gpu_solver.h"
#endif

namespace {

using namespace tender;
using namespace tender::bench;

/// A run the command line asked for, checked before anything runs.
struct BenchRun {
  BenchOptions o;
  std::vector<Size> sizes;
  std::vector<std::string> backends;
  OutputSet outputs;
  uint32_t cpu_threads = 0; ///< the preset's CPU solver threads, for the host's copy bandwidth
  bool anyGpu() const {
    return std::any_of(backends.begin(), backends.end(), [](const std::string& b) { return b != "cpu"; });
  }
};

void addOptions(CLI::App& app, BenchOptions& o, std::string& max_cpu_particles, std::string& batches) {
  app.set_version_flag("--version", std::string("tender-bench ") + TENDER_VERSION);
  app.add_option("--sizes", o.sizes, "grid sizes, WxH comma-separated")->capture_default_str();
  app.add_option("--backends", o.backends, "cpu, gpu, gpu-percolor (GPU without the fused small-sheet path)")
      ->capture_default_str();
  app.add_option("--preset", o.preset, "tender, crumple, tender-low or crumple-low")->capture_default_str();
  app.add_option("--set", o.sets, "override a parameter: key=value (repeatable; applied after the size scaling)");
  app.add_option("--ticks", o.ticks, "timed ticks per case")->check(CLI::Range(1u, 1000000u))->capture_default_str();
  app.add_option("--warmup", o.warmup, "untimed ticks first")->check(CLI::Range(0u, 1000000u))->capture_default_str();
  app.add_option("--device", o.device, "Vulkan device index (see `tender devices`)");
  app.add_option("--fused-workgroup", o.fused_workgroup,
                 "invocations of the GPU's fused tick's workgroup (0: the device kind's; at most 1024 and the "
                 "device's limit)")
      ->check(CLI::Range(0u, 1024u))
      ->capture_default_str();
  app.add_option("--json", o.json, "write the results as JSON here");
  app.add_option("--csv", o.csv, "write the results as CSV here");
  app.add_option("--max-cpu-particles", max_cpu_particles, "skip CPU cases with more particles")->capture_default_str();
  app.add_option("--max-seconds", o.max_seconds, "time budget of one case's timed ticks (at least 3 run)")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  app.add_option("--batch", batches,
                 "fleets of these many sheets per size and backend (comma-separated, e.g. 1,16,256,4096): "
                 "sheet-ticks per second against single-sheet runs");
  app.add_flag("--no-peak", o.no_peak, "skip the copy-bandwidth measurement (no percent of peak in the results)");
}

/// The preset with its --set overrides, checked; gives the CPU solver's threads.
std::optional<std::string> checkPreset(BenchRun& run) {
  auto p = presetParams(run.o.preset);
  if (!p) {
    std::string names;
    for (auto& n : presetNames()) names += (names.empty() ? "" : ", ") + n;
    return "unknown preset '" + run.o.preset + "' (one of " + names + ")";
  }
  for (const std::string& s : run.o.sets) {
    // The grid is --sizes': a `--set cols/rows` would run a sheet the table does not name
    const std::string key = s.substr(0, s.find('='));
    if (key == "cols" || key == "rows") return "--set " + key + ": the grid is set by --sizes (WxH)";
    if (auto err = applyOverride(*p, s)) return err;
  }
  if (auto err = validate(*p, "cpu")) return err;
  run.cpu_threads = p->threads;
  return std::nullopt;
}

/// Checks every option and output before anything runs.
std::optional<std::string> checkRun(BenchRun& run, const std::string& max_cpu_particles, const std::string& batches) {
  BenchOptions& o = run.o;
  if (!std::isfinite(o.max_seconds)) return "--max-seconds: not a number";
  if (auto err = parseWhole(max_cpu_particles, 0, uint64_t(1) << 40, o.max_cpu_particles))
    return "--max-cpu-particles: " + *err;
  for (const std::string& path : {o.json, o.csv})
    if (auto err = run.outputs.add(path)) return err;
  for (const std::string& item : batches.empty() ? std::vector<std::string>{} : split(batches, ',')) {
    uint64_t b = 0;
    if (auto err = parseWhole(item, 1, kMaxBatchSheets, b)) return "--batch '" + item + "': " + *err;
    o.batches.push_back(uint32_t(b));
  }
  if (auto err = parseSizes(o.sizes, run.sizes)) return err;
  run.backends = split(o.backends, ',');
  if (run.backends.empty()) return "--backends is empty";
  for (const std::string& b : run.backends) {
    if (b != "cpu" && b != "gpu" && b != "gpu-percolor")
      return "unknown backend '" + b + "' (cpu, gpu or gpu-percolor)";
    if (b != "cpu" && !vulkanBuilt()) return "this build has no GPU backend (try --backends cpu)";
  }
  return checkPreset(run);
}

/// The peaks: copy bandwidth over the CPU solver's threads and on the device.
Peaks measurePeaks(const BenchRun& run, nlohmann::json& out, Progress& progress) {
  Peaks peaks;
  out["peak_bandwidth"] = nlohmann::json::object();
  auto record = [&](const char* key, const bench::PeakBandwidth& b) {
    out["peak_bandwidth"][key] = {{"gbps", b.gbps},
                                  {"buffer_bytes", b.buffer_bytes},
                                  {"repetitions", b.repetitions},
                                  {"threads", b.threads},
                                  {"method", b.method}};
    char buf[200];
    std::snprintf(buf, sizeof(buf), "peak %s: %.2f GB/s (%s, %s, best of %u)", key, b.gbps, b.method.c_str(),
                  humanBytes(b.buffer_bytes).c_str(), b.repetitions);
    progress.update(buf, true);
  };
  if (run.o.no_peak) return peaks;
  if (std::find(run.backends.begin(), run.backends.end(), "cpu") != run.backends.end()) {
    peaks.cpu = bench::measureHostCopy(run.cpu_threads);
    record("cpu", *peaks.cpu);
  }
#ifdef TENDER_HAS_GPU
  if (run.anyGpu()) {
    std::string error;
    peaks.gpu = bench::measureDeviceCopy(run.o.device, error);
    if (peaks.gpu) {
      record("gpu", *peaks.gpu);
    } else {
      out["peak_bandwidth"]["gpu"] = {{"skipped", error}};
      progress.update("peak gpu: skipped (" + error + ")", true);
    }
  }
#endif
  return peaks;
}

#ifdef TENDER_HAS_GPU
/// What one empty dispatch and its barrier cost on the device (a fraction of a second: measured
/// with --no-peak too).
void recordDispatchCost(gpu::VulkanContext& ctx, nlohmann::json& out, Progress& progress) {
  std::string error;
  if (auto cost = bench::measureDispatchCost(ctx, error)) {
    out["dispatch_cost"]["gpu"] = {{"dispatch_us", cost->us},
                                   {"chain", cost->chain},
                                   {"repetitions", cost->repetitions},
                                   {"samples_us", cost->samples_us},
                                   {"device", ctx.properties().deviceName},
                                   {"method", cost->method}};
    char buf[160];
    std::snprintf(buf, sizeof(buf), "dispatch gpu: %.2f us per empty dispatch + barrier (median of %u chains of %u, ",
                  cost->us, cost->repetitions, cost->chain);
    progress.update(buf + std::string(ctx.properties().deviceName) + ")", true);
  } else {
    out["dispatch_cost"]["gpu"] = {{"skipped", error}};
    progress.update("dispatch gpu: skipped (" + error + ")", true);
  }
}
#endif

/// Every size on every backend, and its fleets.
void runCases(const BenchRun& run, const Peaks& peaks, nlohmann::json& out, Progress& progress) {
  const BenchOptions& o = run.o;
  const size_t total = run.sizes.size() * run.backends.size() * (1 + o.batches.size());
  size_t index = 0;
  out["batches"] = nlohmann::json::array();
  for (const Size& size : run.sizes)
    for (const std::string& backend : run.backends) {
      auto label = [&](const std::string& what) {
        return "[" + std::to_string(++index) + "/" + std::to_string(total) + "] " + size.text() + " " + backend + what;
      };
      nlohmann::json r = runCase(o, peaks, size, backend, label(""), progress);
      if (r.contains("device")) out["machine"]["gpu"] = r["device"];
      const double single_ms = r["status"] == "ok" ? r["ms_median"].get<double>() : 0.0;
      out["results"].push_back(r);
      // Fleets run on cpu and gpu (the fused tick); gpu-percolor has none.
      for (uint32_t b : o.batches)
        if (backend == "gpu-percolor")
          ++index;
        else
          out["batches"].push_back(
              runBatchCase(o, size, backend, b, single_ms, label(" batch " + std::to_string(b)), progress));
    }
}

} // namespace

int main(int argc, char** argv) {
  BenchRun run;
  run.o.backends = vulkanBuilt() ? "cpu,gpu" : "cpu";
  setProgramName("tender-bench");
  CLI::App app{"tender-bench: how the solvers scale with the size of the sheet."};
  std::string max_cpu_particles = std::to_string(run.o.max_cpu_particles), batches;
  addOptions(app, run.o, max_cpu_particles, batches);
  if (const std::optional<int> status = parseArgs(app, argc, argv)) return *status;
  // Validate everything before running anything: options, outputs, the device.
  if (auto err = checkRun(run, max_cpu_particles, batches)) return fail(*err);
#ifdef TENDER_HAS_GPU
  // The device's context, kept for the dispatch cost (released before the cases run).
  std::unique_ptr<gpu::VulkanContext> device_ctx;
  if (run.anyGpu()) {
    gpu::ContextOptions co;
    co.device = run.o.device;
    auto ctx = gpu::VulkanContext::create(co);
    if (!ctx) return fail(ctx.error() + " (try --backends cpu)");
    device_ctx = std::move(ctx.value());
  }
#endif

  const BenchOptions& o = run.o;
  nlohmann::json out;
  out["tool"] = "tender-bench";
  out["version"] = TENDER_VERSION;
  out["machine"] = {{"cpu_model", cpuModel()}, {"cores", std::thread::hardware_concurrency()}};
  out["preset"] = o.preset;
  out["ticks"] = o.ticks;
  out["warmup"] = o.warmup;
  out["sets"] = o.sets;
  out["results"] = nlohmann::json::array();
  Progress progress;
  const Peaks peaks = measurePeaks(run, out, progress);
  out["dispatch_cost"] = nlohmann::json::object();
#ifdef TENDER_HAS_GPU
  if (device_ctx) recordDispatchCost(*device_ctx, out, progress);
  device_ctx.reset();
#endif
  runCases(run, peaks, out, progress);

  printTable(out["results"]);
  if (!o.batches.empty()) printBatchTable(out["batches"]);
  if (!o.json.empty())
    if (auto err = run.outputs.stage(o.json, out.dump(2) + "\n")) return fail(*err);
  if (!o.csv.empty())
    if (auto err = run.outputs.stage(o.csv, csvText(out["results"]))) return fail(*err);
  if (auto err = run.outputs.commit()) return fail(*err);
  return finishOutput(0); // the tables must reach standard output
}
