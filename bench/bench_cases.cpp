// The cases of tender-bench (bench_cases.h).
#include "bench_cases.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>

#include "backend/backend.h"
#include "core/fleet.h"
#include "core/simulation.h"
#include "core/stats.h"
#include "cpu/cpu_batch.h"
#include "cpu/cpu_solver.h"

#ifdef TENDER_HAS_GPU
#include "dispatch_cost.h"
#include "gpu/gpu_solver.h"
#endif

namespace tender::bench {
namespace {

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double pos = q * double(v.size() - 1);
  const size_t lo = size_t(std::floor(pos)), hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (v[hi] - v[lo]) * (pos - double(lo));
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

} // namespace

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

namespace {

/// The tick's memory layout and pair lists, for its traffic (bench/traffic.h); recorded in `r`.
struct SolverShape {
  Layout layout = Layout::Cpu;
  bool candidate_lists = false;
};

SolverShape describeSolver(const Backend& made, Simulation& sim, nlohmann::json& r) {
  SolverShape shape;
  if (CpuSolver* cpu = made.cpu) {
    r["threads"] = cpu->threadCount();
    shape.candidate_lists = cpu->usesCandidateLists();
    r["candidate_lists"] = shape.candidate_lists;
  } else {
    r["threads"] = 0;
  }
#ifdef TENDER_HAS_GPU
  if (gpu::GpuSolver* gpu_solver = made.gpu) {
    r["device"] = std::string(gpu_solver->context().properties().deviceName);
    const bool fused = gpu_solver->usesFusedPath(sim.makeUniforms());
    r["fused"] = fused;
    r["fused_workgroup"] = gpu_solver->fusedWorkgroup();
    shape.layout = fused ? Layout::GpuFused : Layout::Gpu;
    shape.candidate_lists = gpu_solver->usesCandidateLists();
    r["candidate_lists"] = shape.candidate_lists;
  }
#else
  (void)sim;
#endif
  return shape;
}

/// Each timed tick's milliseconds, and each pass's.
struct TickTimes {
  std::vector<double> ms;
  std::map<std::string, std::vector<double>> pass_ms;
};

TickTimes timeTicks(const BenchOptions& o, Simulation& sim, Solver& solver, const std::string& label,
                    Progress& progress) {
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
    sim.tick();
    solver.finish();
    show("warm-up", t + 1, o.warmup);
    if (elapsed() > o.max_seconds / 2) break; // a slow size gets a short warm-up
  }
  TickTimes times;
  const auto timed_start = Clock::now();
  for (uint32_t t = 0; t < o.ticks; ++t) {
    const auto t0 = Clock::now();
    sim.tick();
    solver.finish();
    times.ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    for (auto& [name, v] : solver.passTimes().ms) times.pass_ms[name].push_back(v);
    show("tick", t + 1, o.ticks);
    // Stop a slow size once the time budget is spent (it still gets 3 ticks).
    if (t + 1 >= 3 && std::chrono::duration<double>(Clock::now() - timed_start).count() > o.max_seconds) break;
  }
  return times;
}

/// Bandwidth: the bytes a tick must move over the median tick (and each timed pass over its own
/// median), against the measured copy bandwidth of the device that ran it. Gives the progress
/// line's tail.
std::string recordTraffic(nlohmann::json& r, Simulation& sim, const SolverShape& shape,
                          const std::optional<PeakBandwidth>& peak) {
  const double median = r["ms_median"].get<double>();
  const nlohmann::json& passes = r["pass_ms"];
  uint64_t bytes = 0;
  nlohmann::json pass_bytes = nlohmann::json::object(), pass_gbps = nlohmann::json::object();
  for (const PassTraffic& t : tickTraffic(sim.topology(), sim.makeUniforms(), shape.layout, shape.candidate_lists)) {
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
  char buf[100];
  std::snprintf(buf, sizeof(buf), "%.1f MB/tick, %.2f GB/s", double(bytes) / 1e6, gbps);
  std::string tail = buf;
  if (peak && peak->gbps > 0.0) {
    r["peak_gbps"] = peak->gbps;
    r["peak_pct"] = 100.0 * gbps / peak->gbps;
    tail += " = " + std::to_string(int(std::lround(100.0 * gbps / peak->gbps))) + "% of peak";
  }
  return tail;
}

} // namespace

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
  bo.fused_workgroup = o.fused_workgroup;
  Backend made;
  std::optional<Simulation> sim;
  try {
    if (auto err = createBackend(bo, made)) return skip(*err);
    sim.emplace(p, *made.solver);
  } catch (const std::exception& e) { // e.g. the device cannot hold the sheet
    return skip(e.what());
  }
  Solver* solver = made.solver.get();
  const SolverShape shape = describeSolver(made, *sim, r);
  const TickTimes times = timeTicks(o, *sim, *solver, label, progress);
  const std::vector<double>& ms = times.ms;
  solver->computeNormals();
  SimState state;
  solver->readback(state);
  const SheetStats st = computeStats(state, p.substepDt());

  const double median = percentile(ms, 0.5);
  r["status"] = "ok";
  r["ticks_measured"] = ms.size();
  r["ms_median"] = median;
  r["ms_p95"] = percentile(ms, 0.95);
  double sum = 0.0;
  for (double v : ms) sum += v;
  r["ms_mean"] = sum / double(ms.size());
  r["ms_min"] = *std::min_element(ms.begin(), ms.end());
  r["particle_substeps_per_s"] = median > 0.0 ? double(p.particleCount()) * p.substeps * 1000.0 / median : 0.0;
  r["dispatches_per_tick"] = solver->dispatchesPerTick();
  r["barrier_phases_per_tick"] = solver->barrierPhasesPerTick();
  r["memory_bytes"] = solver->memoryBytes();
  nlohmann::json passes = nlohmann::json::object();
  for (auto& [name, v] : times.pass_ms) passes[name] = percentile(v, 0.5);
  r["pass_ms"] = passes;
  const std::string traffic = recordTraffic(r, *sim, shape, backend == "cpu" ? peaks.cpu : peaks.gpu);
  r["torn"] = st.torn;
  r["nan_count"] = st.nan_count;
  r["state_hash"] = hashHex(st.state_hash);
  char buf[300];
  std::snprintf(buf, sizeof(buf), "%s: %.3f ms/tick median, %.3f p95 (%zu ticks); %s", label.c_str(), median,
                percentile(ms, 0.95), ms.size(), traffic.c_str());
  progress.update(buf, true);
  return r;
}

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
  bo.fused_workgroup = o.fused_workgroup;
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
  r["state_hash"] = hashHex(st.state_hash);
  char buf[300];
  std::snprintf(
      buf, sizeof(buf), "%s: %.3f ms per batched tick, %.0f sheet-ticks/s%s", label.c_str(), median, sheet_ticks,
      single_ms > 0.0
          ? (", " + std::to_string(sheet_ticks / (1000.0 / single_ms)).substr(0, 5) + "x single-sheet runs").c_str()
          : "");
  progress.update(buf, true);
  return r;
}

} // namespace tender::bench
