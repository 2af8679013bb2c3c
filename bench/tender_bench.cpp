// tender-bench: scaling benchmark of the solvers. For each sheet size and backend it runs the full
// physics (every substep, iteration, collision and tear check of the preset) and reports ms per
// tick (median, p95), particle-substeps per second, dispatches per tick, memory, the bytes a tick
// must move (bench/traffic.h) and the bandwidth that achieves against the machine's measured copy
// bandwidth and, on the GPU, the time and bandwidth of each pass and what one empty dispatch and
// its barrier cost on the device (bench/dispatch_cost.h). Bench sizes keep the sheet's physical
// size: spacing and hash cell scale with the grid (see bench/README.md).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "backend/backend.h"
#include "cli/cli.h"
#include "core/fleet.h"
#include "core/output.h"
#include "core/simulation.h"
#include "core/stats.h"
#include "cpu/cpu_batch.h"
#include "cpu/cpu_solver.h"
#include "traffic.h"

#ifdef TENDER_HAS_GPU
#include "dispatch_cost.h"
#include "gpu/gpu_solver.h"
#endif

namespace tender {
namespace {

/// Command-line options.
struct BenchOptions {
  std::string sizes = "32x48,64x96,128x192,256x384,512x768,1024x1536,2048x3072";
  std::string backends;
  std::string preset = "tender";
  std::vector<std::string> sets;
  uint32_t ticks = 60;
  uint32_t warmup = 10;
  int device = -1;
  std::string json, csv;
  uint64_t max_cpu_particles = 400000;
  double max_seconds = 30.0;
  bool no_peak = false;          ///< skip the copy-bandwidth measurement of the host and the device
  std::vector<uint32_t> batches; ///< --batch: fleets of these many sheets per size and backend
};

/// Measured copy bandwidths that results are compared with (absent: not measured).
struct Peaks {
  std::optional<bench::PeakBandwidth> cpu, gpu;
};

/// One grid size.
struct Size {
  uint32_t cols = 0, rows = 0;
  std::string text() const { return std::to_string(cols) + "x" + std::to_string(rows); }
};

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, sep)) out.push_back(item);
  if (!s.empty() && s.back() == sep) out.push_back("");
  return out;
}

// Parses "32x48,128x192"; returns an error message.
std::optional<std::string> parseSizes(const std::string& text, std::vector<Size>& out) {
  if (text.empty()) return std::string("--sizes is empty");
  for (const std::string& item : split(text, ',')) {
    const size_t x = item.find_first_of("xX");
    uint64_t cols = 0, rows = 0;
    if (x == std::string::npos || parseWhole(item.substr(0, x), 0, ~uint64_t(0), cols) ||
        parseWhole(item.substr(x + 1), 0, ~uint64_t(0), rows))
      return "bad size '" + item + "' (expected WxH, e.g. 128x192)";
    if (cols < 2 || rows < 2 || cols > 16384 || rows > 16384)
      return "size '" + item + "' is out of range (2 to 16384 per side)";
    out.push_back({uint32_t(cols), uint32_t(rows)});
  }
  return std::nullopt;
}

std::string cpuModel() {
  std::ifstream f("/proc/cpuinfo");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind("model name", 0) == 0) {
      auto colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(' ', colon + 1));
    }
  return "unknown";
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double pos = q * double(v.size() - 1);
  const size_t lo = size_t(std::floor(pos)), hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (v[hi] - v[lo]) * (pos - double(lo));
}

std::string hex64(uint64_t v) {
  char buf[20];
  std::snprintf(buf, sizeof(buf), "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

/// Parameters of one bench size: the preset, the grid, spacing and hash cell scaled so the sheet
/// keeps the preset's width, then the user's overrides (which win).
std::optional<std::string> benchParams(const BenchOptions& o, const Size& size, SimParams& out) {
  auto p = presetParams(o.preset);
  if (!p) return "unknown preset '" + o.preset + "'";
  const float scale = float(p->cols - 1) / float(size.cols - 1);
  p->cols = size.cols;
  p->rows = size.rows;
  p->spacing *= scale;
  p->cell_size *= scale;
  for (const std::string& s : o.sets)
    if (auto err = applyOverride(*p, s)) return err;
  out = *p;
  return std::nullopt;
}

/// Progress on stderr: one line rewritten in place on a terminal, a line per case otherwise.
class Progress {
public:
  Progress() : tty_(isatty(STDERR_FILENO) != 0) {}
  void update(const std::string& text, bool final_line) {
    if (tty_) {
      std::fprintf(stderr, "\r%-100s%s", text.c_str(), final_line ? "\n" : "");
    } else if (final_line) {
      std::fprintf(stderr, "%s\n", text.c_str());
    }
    std::fflush(stderr);
  }
  bool live() const { return tty_; }

private:
  bool tty_;
};

/// The JSON record of a case: its size and backend.
nlohmann::json caseRecord(const Size& size, const std::string& backend) {
  nlohmann::json r;
  r["size"] = size.text();
  r["cols"] = size.cols;
  r["rows"] = size.rows;
  r["particles"] = uint64_t(size.cols) * size.rows;
  r["backend"] = backend;
  return r;
}

/// Marks record `r` skipped with the reason, says so, and returns it.
auto skipper(nlohmann::json& r, const std::string& label, Progress& progress) {
  return [&r, &label, &progress](const std::string& why) {
    r["status"] = "skipped";
    r["reason"] = why;
    progress.update(label + ": skipped (" + why + ")", true);
    return r;
  };
}

/// The parameters of a case (benchParams), checked for the backend; returns why they cannot run.
std::optional<std::string> caseParams(const BenchOptions& o, const Size& size, const std::string& backend,
                                      SimParams& p) {
  if (auto err = benchParams(o, size, p)) return err;
  return validate(p, backend);
}

/// Runs one size on one backend and returns its JSON record.
nlohmann::json runCase(const BenchOptions& o, const Peaks& peaks, const Size& size, const std::string& backend,
                       const std::string& label, Progress& progress) {
  nlohmann::json r = caseRecord(size, backend);
  auto skip = skipper(r, label, progress);
  SimParams p;
  if (auto err = caseParams(o, size, backend, p)) return skip(*err);
  if (backend == "cpu" && uint64_t(p.particleCount()) > o.max_cpu_particles)
    return skip("over --max-cpu-particles " + std::to_string(o.max_cpu_particles));
  r["spacing"] = p.spacing;
  r["cell_size"] = p.cell_size;
  r["substeps"] = p.substeps;
  r["iterations"] = p.iterations;

  BackendOptions bo = backendOptionsFor(backend, p);
  bo.device = o.device;
  Backend made;
  std::optional<Simulation> sim;
  try {
    if (auto err = createBackend(bo, made)) return skip(*err);
    sim.emplace(p, *made.solver);
  } catch (const std::exception& e) { // e.g. the device cannot hold the sheet
    return skip(e.what());
  }
  Solver* solver = made.solver.get();
  bool candidate_lists = false;
  if (CpuSolver* cpu = made.cpu) {
    r["threads"] = cpu->threadCount();
    candidate_lists = cpu->usesCandidateLists();
    r["candidate_lists"] = candidate_lists;
  } else {
    r["threads"] = 0;
  }
#ifdef TENDER_HAS_GPU
  bench::Layout layout = bench::Layout::Cpu;
  if (gpu::GpuSolver* gpu_solver = made.gpu) {
    r["device"] = std::string(gpu_solver->context().properties().deviceName);
    const bool fused = gpu_solver->usesFusedPath(sim->makeUniforms());
    r["fused"] = fused;
    layout = fused ? bench::Layout::GpuFused : bench::Layout::Gpu;
    candidate_lists = gpu_solver->usesCandidateLists();
    r["candidate_lists"] = candidate_lists;
  }
#else
  const bench::Layout layout = bench::Layout::Cpu;
#endif

  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  auto show = [&](const char* phase, uint32_t done, uint32_t total) {
    if (!progress.live()) return;
    char buf[160];
    std::snprintf(buf, sizeof(buf), "%s: %s %u/%u (%.1f s)", label.c_str(), phase, done, total, elapsed());
    progress.update(buf, false);
  };
  for (uint32_t t = 0; t < o.warmup; ++t) {
    sim->tick();
    solver->finish();
    show("warm-up", t + 1, o.warmup);
    if (elapsed() > o.max_seconds / 2) break; // a slow size gets a short warm-up
  }
  std::vector<double> ms;
  std::map<std::string, std::vector<double>> pass_ms;
  const auto timed_start = Clock::now();
  for (uint32_t t = 0; t < o.ticks; ++t) {
    const auto t0 = Clock::now();
    sim->tick();
    solver->finish();
    ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    for (auto& [name, v] : solver->passTimes().ms) pass_ms[name].push_back(v);
    show("tick", t + 1, o.ticks);
    // Stop a slow size once the time budget is spent (it still gets 3 ticks).
    if (t + 1 >= 3 && std::chrono::duration<double>(Clock::now() - timed_start).count() > o.max_seconds) break;
  }
  solver->computeNormals();
  SimState state;
  solver->readback(state);
  const SheetStats st = computeStats(state, p.substepDt());

  const double median = percentile(ms, 0.5);
  r["status"] = "ok";
  r["ticks_measured"] = ms.size();
  r["ms_median"] = median;
  r["ms_p95"] = percentile(ms, 0.95);
  r["ms_mean"] = [&] {
    double s = 0.0;
    for (double v : ms) s += v;
    return s / double(ms.size());
  }();
  r["ms_min"] = *std::min_element(ms.begin(), ms.end());
  r["particle_substeps_per_s"] = median > 0.0 ? double(p.particleCount()) * p.substeps * 1000.0 / median : 0.0;
  r["dispatches_per_tick"] = solver->dispatchesPerTick();
  r["memory_bytes"] = solver->memoryBytes();
  nlohmann::json passes = nlohmann::json::object();
  for (auto& [name, v] : pass_ms) passes[name] = percentile(v, 0.5);
  r["pass_ms"] = passes;

  // Bandwidth: the bytes a tick must move over the median tick (and each timed pass over its own
  // median), against the measured copy bandwidth of the device that ran it.
  uint64_t bytes = 0;
  nlohmann::json pass_bytes = nlohmann::json::object(), pass_gbps = nlohmann::json::object();
  for (const bench::PassTraffic& t :
       bench::tickTraffic(sim->topology(), sim->makeUniforms(), layout, candidate_lists)) {
    bytes += t.bytes();
    pass_bytes[t.name] = {{"read", t.read}, {"write", t.write}};
    if (passes.contains(t.name) && passes[t.name].get<double>() > 0.0 && t.bytes() > 0)
      pass_gbps[t.name] = double(t.bytes()) / (passes[t.name].get<double>() * 1e6);
  }
  const double gbps = median > 0.0 ? double(bytes) / (median * 1e6) : 0.0;
  r["bytes_per_tick"] = bytes;
  r["pass_bytes"] = pass_bytes;
  r["achieved_gbps"] = gbps;
  r["pass_gbps"] = pass_gbps;
  const std::optional<bench::PeakBandwidth>& peak = backend == "cpu" ? peaks.cpu : peaks.gpu;
  std::string vs_peak;
  if (peak && peak->gbps > 0.0) {
    r["peak_gbps"] = peak->gbps;
    r["peak_pct"] = 100.0 * gbps / peak->gbps;
    vs_peak = " = " + std::to_string(int(std::lround(100.0 * gbps / peak->gbps))) + "% of peak";
  }
  r["torn"] = st.torn;
  r["nan_count"] = st.nan_count;
  r["state_hash"] = hex64(st.state_hash);
  char buf[300];
  std::snprintf(buf, sizeof(buf), "%s: %.3f ms/tick median, %.3f p95 (%zu ticks); %.1f MB/tick, %.2f GB/s%s",
                label.c_str(), median, percentile(ms, 0.95), ms.size(), double(bytes) / 1e6, gbps, vs_peak.c_str());
  progress.update(buf, true);
  return r;
}

/// Runs a fleet of `sheets` sheets of one size on one backend (each sheet the full physics of the
/// preset) and returns its JSON record: ms per batched tick, sheet-ticks and particle-substeps per
/// second, and the speed-up over single-sheet runs of the same size (`single_ms`, per tick).
nlohmann::json runBatchCase(const BenchOptions& o, const Size& size, const std::string& backend, uint32_t sheets,
                            double single_ms, const std::string& label, Progress& progress) {
  nlohmann::json r = caseRecord(size, backend);
  r["batch"] = sheets;
  auto skip = skipper(r, label, progress);
  SimParams p;
  if (auto err = caseParams(o, size, backend, p)) return skip(*err);
  if (auto err = batchMemoryError(p, backend, sheets, o.device)) return skip(*err);
  BackendOptions bo = backendOptionsFor(backend, p);
  bo.device = o.device;
  std::unique_ptr<SheetBatch> batch;
  std::optional<Fleet> fleet;
  try {
    if (auto err = createBatch(bo, sheets, batch)) return skip(*err);
    fleet.emplace(*batch, std::vector<FleetSheet>(sheets, FleetSheet{p, {}}));
  } catch (const std::exception& e) { // e.g. the device cannot hold the batch
    return skip(e.what());
  }
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  for (uint32_t t = 0; t < o.warmup && elapsed() < o.max_seconds / 2; ++t) {
    fleet->tick();
    batch->finish();
  }
  std::vector<double> ms;
  const auto timed_start = Clock::now();
  for (uint32_t t = 0; t < o.ticks; ++t) {
    const auto t0 = Clock::now();
    fleet->tick();
    batch->finish();
    ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    if (progress.live()) progress.update(label + ": tick " + std::to_string(t + 1), false);
    if (t + 1 >= 3 && std::chrono::duration<double>(Clock::now() - timed_start).count() > o.max_seconds) break;
  }
  SimState state;
  fleet->sim(0).solver().readback(state);
  const SheetStats st = computeStats(state, p.substepDt());
  const double median = percentile(ms, 0.5);
  const double sheet_ticks = median > 0.0 ? 1000.0 * sheets / median : 0.0;
  r["status"] = "ok";
  r["ticks_measured"] = ms.size();
  r["ms_median"] = median;
  r["ms_p95"] = percentile(ms, 0.95);
  r["sheet_ticks_per_s"] = sheet_ticks;
  r["particle_substeps_per_s"] = sheet_ticks * double(p.particleCount()) * p.substeps;
  r["dispatches_per_tick"] = batch->dispatchesPerFlush();
  r["memory_bytes"] = batch->memoryBytes();
  if (single_ms > 0.0) {
    r["single_ms_median"] = single_ms;
    r["speedup_vs_single"] = sheet_ticks / (1000.0 / single_ms);
  }
  if (backend == "cpu") r["threads"] = static_cast<CpuBatch&>(*batch).threads();
  r["torn"] = st.torn;
  r["nan_count"] = st.nan_count;
  r["state_hash"] = hex64(st.state_hash);
  char buf[300];
  std::snprintf(
      buf, sizeof(buf), "%s: %.3f ms per batched tick, %.0f sheet-ticks/s%s", label.c_str(), median, sheet_ticks,
      single_ms > 0.0
          ? (", " + std::to_string(sheet_ticks / (1000.0 / single_ms)).substr(0, 5) + "x single-sheet runs").c_str()
          : "");
  progress.update(buf, true);
  return r;
}

std::string humanBytes(uint64_t b) {
  char buf[32];
  if (b >= (1ull << 30))
    std::snprintf(buf, sizeof(buf), "%.2f GiB", double(b) / double(1ull << 30));
  else if (b >= (1ull << 20))
    std::snprintf(buf, sizeof(buf), "%.1f MiB", double(b) / double(1ull << 20));
  else
    std::snprintf(buf, sizeof(buf), "%.1f KiB", double(b) / 1024.0);
  return buf;
}

void printTable(const nlohmann::json& results) {
  std::printf("%-11s %-12s %9s %7s %10s %10s %14s %11s %10s %10s %8s %6s\n", "size", "backend", "particles", "threads",
              "ms median", "ms p95", "part-substep/s", "dispatches", "memory", "MB/tick", "GB/s", "%peak");
  for (const auto& r : results) {
    if (r["status"] != "ok") {
      std::printf("%-11s %-12s %9llu  skipped: %s\n", r["size"].get<std::string>().c_str(),
                  r["backend"].get<std::string>().c_str(),
                  static_cast<unsigned long long>(r["particles"].get<uint64_t>()),
                  r["reason"].get<std::string>().c_str());
      continue;
    }
    const std::string pct = r.contains("peak_pct") ? std::to_string(std::lround(r["peak_pct"].get<double>())) : "-";
    std::printf("%-11s %-12s %9llu %7u %10.3f %10.3f %14.3g %11u %10s %10.1f %8.2f %6s\n",
                r["size"].get<std::string>().c_str(), r["backend"].get<std::string>().c_str(),
                static_cast<unsigned long long>(r["particles"].get<uint64_t>()), r["threads"].get<uint32_t>(),
                r["ms_median"].get<double>(), r["ms_p95"].get<double>(), r["particle_substeps_per_s"].get<double>(),
                r["dispatches_per_tick"].get<uint32_t>(), humanBytes(r["memory_bytes"].get<uint64_t>()).c_str(),
                double(r["bytes_per_tick"].get<uint64_t>()) / 1e6, r["achieved_gbps"].get<double>(), pct.c_str());
    if (!r["pass_ms"].empty()) {
      std::printf("%-11s   passes (ms, GB/s):", "");
      for (auto& [name, v] : r["pass_ms"].items()) {
        std::printf(" %s %.4f", name.c_str(), v.get<double>());
        if (r["pass_gbps"].contains(name)) std::printf(" (%.2f)", r["pass_gbps"][name].get<double>());
      }
      std::printf("\n");
    }
  }
}

void printBatchTable(const nlohmann::json& batches) {
  std::printf("\n%-11s %-8s %6s %14s %14s %16s %10s %11s %10s\n", "size", "backend", "batch", "ms/batch tick",
              "sheet-ticks/s", "part-substep/s", "x single", "dispatches", "memory");
  for (const auto& r : batches) {
    if (r["status"] != "ok") {
      std::printf("%-11s %-8s %6u  skipped: %s\n", r["size"].get<std::string>().c_str(),
                  r["backend"].get<std::string>().c_str(), r["batch"].get<uint32_t>(),
                  r["reason"].get<std::string>().c_str());
      continue;
    }
    const std::string speedup = r.contains("speedup_vs_single")
                                    ? std::to_string(r["speedup_vs_single"].get<double>()).substr(0, 5)
                                    : std::string("-");
    std::printf("%-11s %-8s %6u %14.3f %14.0f %16.3g %10s %11u %10s\n", r["size"].get<std::string>().c_str(),
                r["backend"].get<std::string>().c_str(), r["batch"].get<uint32_t>(), r["ms_median"].get<double>(),
                r["sheet_ticks_per_s"].get<double>(), r["particle_substeps_per_s"].get<double>(), speedup.c_str(),
                r["dispatches_per_tick"].get<uint32_t>(), humanBytes(r["memory_bytes"].get<uint64_t>()).c_str());
  }
}

std::string csvText(const nlohmann::json& results) {
  std::ostringstream f;
  f << "size,cols,rows,particles,backend,status,threads,ticks_measured,ms_median,ms_p95,ms_mean,ms_min,"
       "particle_substeps_per_s,dispatches_per_tick,memory_bytes,bytes_per_tick,achieved_gbps,peak_gbps,peak_pct,torn,"
       "state_hash,passes,pass_bytes,pass_gbps\n";
  for (const auto& r : results) {
    auto num = [&](const char* k) -> std::string { return r.contains(k) ? r[k].dump() : ""; };
    // name=value;name=value (pass_bytes: read + write)
    auto list = [&](const char* k) {
      std::string out;
      if (r.contains(k))
        for (auto& [name, v] : r[k].items())
          out += (out.empty() ? "" : ";") + name + "=" +
                 (v.is_object() ? std::to_string(v["read"].get<uint64_t>() + v["write"].get<uint64_t>()) : v.dump());
      return out;
    };
    f << r["size"].get<std::string>() << ',' << num("cols") << ',' << num("rows") << ',' << num("particles") << ','
      << r["backend"].get<std::string>() << ',' << r["status"].get<std::string>() << ',' << num("threads") << ','
      << num("ticks_measured") << ',' << num("ms_median") << ',' << num("ms_p95") << ',' << num("ms_mean") << ','
      << num("ms_min") << ',' << num("particle_substeps_per_s") << ',' << num("dispatches_per_tick") << ','
      << num("memory_bytes") << ',' << num("bytes_per_tick") << ',' << num("achieved_gbps") << ',' << num("peak_gbps")
      << ',' << num("peak_pct") << ',' << num("torn") << ','
      << (r.contains("state_hash") ? r["state_hash"].get<std::string>() : "") << ',' << list("pass_ms") << ','
      << list("pass_bytes") << ',' << list("pass_gbps") << '\n';
  }
  return f.str();
}

} // namespace
} // namespace tender

int main(int argc, char** argv) {
  using namespace tender;
  BenchOptions o;
  o.backends = vulkanBuilt() ? "cpu,gpu" : "cpu";
  setProgramName("tender-bench");
  CLI::App app{"tender-bench: how the solvers scale with the size of the sheet."};
  app.set_version_flag("--version", std::string("tender-bench ") + TENDER_VERSION);
  app.add_option("--sizes", o.sizes, "grid sizes, WxH comma-separated")->capture_default_str();
  app.add_option("--backends", o.backends, "cpu, gpu, gpu-percolor (GPU without the fused small-sheet path)")
      ->capture_default_str();
  app.add_option("--preset", o.preset, "tender, crumple, tender-low or crumple-low")->capture_default_str();
  app.add_option("--set", o.sets, "override a parameter: key=value (repeatable; applied after the size scaling)");
  app.add_option("--ticks", o.ticks, "timed ticks per case")->check(CLI::Range(1u, 1000000u))->capture_default_str();
  app.add_option("--warmup", o.warmup, "untimed ticks first")->check(CLI::Range(0u, 1000000u))->capture_default_str();
  app.add_option("--device", o.device, "Vulkan device index (see `tender devices`)");
  app.add_option("--json", o.json, "write the results as JSON here");
  app.add_option("--csv", o.csv, "write the results as CSV here");
  std::string max_cpu_particles = std::to_string(o.max_cpu_particles);
  app.add_option("--max-cpu-particles", max_cpu_particles, "skip CPU cases with more particles")->capture_default_str();
  app.add_option("--max-seconds", o.max_seconds, "time budget of one case's timed ticks (at least 3 run)")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  std::string batches;
  app.add_option("--batch", batches,
                 "fleets of these many sheets per size and backend (comma-separated, e.g. 1,16,256,4096): "
                 "sheet-ticks per second against single-sheet runs");
  app.add_flag("--no-peak", o.no_peak, "skip the copy-bandwidth measurement (no percent of peak in the results)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) { // --help, --version
    return finishOutput(app.exit(e));
  } catch (const CLI::ParseError& e) {
    return fail(e.what());
  }

  if (auto err = emptyValue(app)) return fail(*err);
  // Validate everything before running anything: options, outputs, the device.
  if (!std::isfinite(o.max_seconds)) return fail("--max-seconds: not a number");
  if (auto err = parseWhole(max_cpu_particles, 0, uint64_t(1) << 40, o.max_cpu_particles))
    return fail("--max-cpu-particles: " + *err);
  OutputSet outputs;
  for (const std::string& path : {o.json, o.csv})
    if (auto err = outputs.add(path)) return fail(*err);
  for (const std::string& item : batches.empty() ? std::vector<std::string>{} : split(batches, ',')) {
    uint64_t b = 0;
    if (auto err = parseWhole(item, 1, kMaxBatchSheets, b)) return fail("--batch '" + item + "': " + *err);
    o.batches.push_back(uint32_t(b));
  }
  uint32_t cpu_threads = 0;
  std::vector<Size> sizes;
  if (auto err = parseSizes(o.sizes, sizes)) return fail(*err);
  std::vector<std::string> backends = split(o.backends, ',');
  if (backends.empty()) return fail("--backends is empty");
  for (const std::string& b : backends) {
    if (b != "cpu" && b != "gpu" && b != "gpu-percolor")
      return fail("unknown backend '" + b + "' (cpu, gpu or gpu-percolor)");
    if (b != "cpu" && !vulkanBuilt()) return fail("this build has no GPU backend (try --backends cpu)");
  }
  {
    auto p = presetParams(o.preset);
    if (!p) {
      std::string names;
      for (auto& n : presetNames()) names += (names.empty() ? "" : ", ") + n;
      return fail("unknown preset '" + o.preset + "' (one of " + names + ")");
    }
    for (const std::string& s : o.sets)
      if (auto err = applyOverride(*p, s)) return fail(*err);
    if (auto err = validate(*p, "cpu")) return fail(*err);
    cpu_threads = p->threads;
  }
#ifdef TENDER_HAS_GPU
  // The device's context, kept for the dispatch cost (released before the cases run).
  std::unique_ptr<gpu::VulkanContext> device_ctx;
  if (std::any_of(backends.begin(), backends.end(), [](const std::string& b) { return b != "cpu"; })) {
    gpu::ContextOptions co;
    co.device = o.device;
    auto ctx = gpu::VulkanContext::create(co);
    if (!ctx) return fail(ctx.error() + " (try --backends cpu)");
    device_ctx = std::move(ctx.value());
  }
#endif

  nlohmann::json out;
  out["tool"] = "tender-bench";
  out["version"] = TENDER_VERSION;
  out["machine"] = {{"cpu_model", cpuModel()}, {"cores", std::thread::hardware_concurrency()}};
  out["preset"] = o.preset;
  out["ticks"] = o.ticks;
  out["warmup"] = o.warmup;
  out["sets"] = o.sets;
  out["results"] = nlohmann::json::array();

  // The peaks: copy bandwidth over the CPU solver's threads and on the device.
  Progress progress;
  Peaks peaks;
  out["peak_bandwidth"] = nlohmann::json::object();
  out["dispatch_cost"] = nlohmann::json::object();
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
  const bool any_cpu = std::find(backends.begin(), backends.end(), "cpu") != backends.end();
  if (!o.no_peak && any_cpu) {
    peaks.cpu = bench::measureHostCopy(cpu_threads);
    record("cpu", *peaks.cpu);
  }
#ifdef TENDER_HAS_GPU
  if (!o.no_peak && std::any_of(backends.begin(), backends.end(), [](const std::string& b) { return b != "cpu"; })) {
    std::string error;
    peaks.gpu = bench::measureDeviceCopy(o.device, error);
    if (peaks.gpu) {
      record("gpu", *peaks.gpu);
    } else {
      out["peak_bandwidth"]["gpu"] = {{"skipped", error}};
      progress.update("peak gpu: skipped (" + error + ")", true);
    }
  }
  // What one empty dispatch and its barrier cost on the device (a fraction of a second: measured
  // with --no-peak too).
  if (device_ctx) {
    std::string error;
    if (auto cost = bench::measureDispatchCost(*device_ctx, error)) {
      out["dispatch_cost"]["gpu"] = {{"dispatch_us", cost->us},
                                     {"chain", cost->chain},
                                     {"repetitions", cost->repetitions},
                                     {"samples_us", cost->samples_us},
                                     {"device", device_ctx->properties().deviceName},
                                     {"method", cost->method}};
      char buf[160];
      std::snprintf(buf, sizeof(buf), "dispatch gpu: %.2f us per empty dispatch + barrier (median of %u chains of %u, ",
                    cost->us, cost->repetitions, cost->chain);
      progress.update(buf + std::string(device_ctx->properties().deviceName) + ")", true);
    } else {
      out["dispatch_cost"]["gpu"] = {{"skipped", error}};
      progress.update("dispatch gpu: skipped (" + error + ")", true);
    }
    device_ctx.reset();
  }
#endif

  const size_t total = sizes.size() * backends.size() * (1 + o.batches.size());
  size_t index = 0;
  out["batches"] = nlohmann::json::array();
  for (const Size& size : sizes)
    for (const std::string& backend : backends) {
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

  printTable(out["results"]);
  if (!o.batches.empty()) printBatchTable(out["batches"]);
  if (!o.json.empty())
    if (auto err = outputs.stage(o.json, out.dump(2) + "\n")) return fail(*err);
  if (!o.csv.empty())
    if (auto err = outputs.stage(o.csv, csvText(out["results"]))) return fail(*err);
  if (auto err = outputs.commit()) return fail(*err);
  return finishOutput(0); // the tables must reach standard output
}
