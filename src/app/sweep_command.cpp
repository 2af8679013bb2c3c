// `tender sweep`: many sheets of one grid, each with its own values of the varied parameters (a
// grid of every combination, or random samples), run in batches that tick together (a Fleet per
// batch); one JSON line of `tender sim`'s stats per sheet. `--shard i/n` runs every n-th sheet, so
// shards run anywhere; `tender sweep-merge` joins their files into the whole sweep's.
#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "core/fleet.h"
#include "core/output.h"
#include "core/progress.h"
#include "core/simulation.h"
#include "core/stats.h"

namespace tender {
namespace {

using Json = nlohmann::ordered_json;

/// Most sheets of one sweep (its lines are held in memory until they are written).
constexpr uint64_t kMaxSweepSheets = 1000000;
/// Sheets per batch when --batch is not given (fewer when memory is short).
constexpr uint64_t kDefaultCpuBatch = 64;
constexpr uint64_t kDefaultGpuBatch = 1024;
/// Stats fields that describe how a sheet's batch ran rather than the sheet: a sweep writes them
/// under "batch", so that everything else on a line depends on the sheet alone.
const char* const kBatchFields[] = {"ms_per_tick", "ms_slowest_tick", "dispatches_per_tick", "gpu_ms_per_pass"};

/// One --vary: a key and its values (a list, or a range a:b:n spelled out), or for --samples a
/// list or a range a:b to draw from.
struct Axis {
  std::string key;
  bool numeric = false, whole = false;
  std::vector<std::string> values; ///< each spelled as `--set` takes it; empty: a sampled range
  double lo = 0.0, hi = 0.0;       ///< the sampled range a:b
};

/// A whole sweep: its base parameters, its axes and how the sheets' values are chosen.
struct Plan {
  SimParams base;
  std::string backend;
  std::vector<Axis> axes;
  uint64_t samples = 0; ///< 0: the grid of every combination
  uint64_t seed = 0;
  uint64_t sheets = 0;
  uint64_t ticks = 0;
  uint64_t shard = 0, shards = 1;
  uint64_t batch = 0; ///< sheets per batch
};

std::string formatNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.9g", v);
  return buf;
}

/// The value of `key` in `p`, spelled as `--set` takes it (the shortest decimal of a float).
std::string spelledValue(const SimParams& p, const std::string& key) {
  for (auto& [k, v] : paramValues(p))
    if (k == key) return v;
  return {};
}

/// `text` applied to `key` over `base` as `--set` would, spelled back as `--set` spells it;
/// returns the error of a bad value.
std::optional<std::string> spelled(const SimParams& base, const std::string& key, const std::string& text,
                                   std::string& out) {
  SimParams p = base;
  if (auto err = applyOverride(p, key + "=" + text)) return err;
  out = spelledValue(p, key);
  return std::nullopt;
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> parts;
  std::string part;
  std::istringstream in(s);
  while (std::getline(in, part, sep)) parts.push_back(part);
  if (!s.empty() && s.back() == sep) parts.push_back("");
  return parts;
}

std::optional<std::string> parseNumber(const std::string& s, double& out) {
  const char* end = s.data() + s.size();
  auto [ptr, ec] = std::from_chars(s.data(), end, out);
  if (s.empty() || ec != std::errc() || ptr != end || !std::isfinite(out)) return "'" + s + "' is not a number";
  return std::nullopt;
}

/// The values of a grid range a:b:n: n evenly spaced from a to b inclusive (n = 1: a), whole
/// numbers rounded to the nearest.
std::vector<std::string> rangeValues(double a, double b, uint64_t n, bool whole) {
  std::vector<std::string> texts;
  for (uint64_t k = 0; k < n; ++k) {
    const double v = k == 0 ? a : k + 1 == n ? b : a + (b - a) * double(k) / double(n - 1);
    texts.push_back(whole ? std::to_string(std::llround(v)) : formatNumber(v));
  }
  return texts;
}

/// Parses one --vary (KEY=v1,v2,... or KEY=a:b:n; KEY=a:b with --samples) over the base
/// parameters, each value checked as `--set` checks it.
std::optional<std::string> parseAxis(const std::string& arg, const SimParams& base, bool sampled, Axis& axis) {
  const auto eq = arg.find('=');
  if (eq == std::string::npos || eq == 0)
    return "--vary '" + arg + "': expected KEY=v1,v2,... or KEY=" + (sampled ? "a:b" : "a:b:n");
  axis.key = arg.substr(0, eq);
  const std::string spec = arg.substr(eq + 1), where = "--vary " + axis.key + ": ";
  const auto info = paramInfo(axis.key);
  if (!info) return "--vary: unknown parameter '" + axis.key + "' (see --help for the keys)";
  const auto& topo = topologyKeys();
  if (std::find(topo.begin(), topo.end(), axis.key) != topo.end())
    return where + axis.key +
           " changes the sheet's topology, which every sheet of a sweep shares (run one sweep per value)";
  if (spec.empty()) return where + "no values";
  axis.numeric = info->lo != info->hi;
  axis.whole = axis.numeric && info->whole;
  std::vector<std::string> texts;
  if (spec.find(':') != std::string::npos) {
    if (!axis.numeric) return where + "takes a list of values (" + axis.key + "=a,b,...), not a range";
    const auto parts = split(spec, ':');
    if (parts.size() != (sampled ? 2u : 3u))
      return where + "'" + spec + "': a range is " + (sampled ? "a:b with --samples" : "a:b:n (n values from a to b)");
    double a = 0.0, b = 0.0;
    if (auto err = parseNumber(parts[0], a)) return where + *err;
    if (auto err = parseNumber(parts[1], b)) return where + *err;
    for (int k = 0; k < 2; ++k) // the ends are values of the key, checked as such
      if (auto err = spelled(base, axis.key, parts[k], texts.emplace_back())) return "--vary " + *err;
    texts.clear();
    if (sampled) {
      axis.lo = a, axis.hi = b;
      return std::nullopt;
    }
    uint64_t n = 0;
    if (auto err = parseWhole(parts[2], 1, kMaxSweepSheets, n)) return where + "count " + *err;
    texts = rangeValues(a, b, n, axis.whole);
  } else {
    texts = split(spec, ',');
  }
  for (const std::string& t : texts) {
    if (t.empty()) return where + "'" + spec + "' has an empty value";
    if (auto err = spelled(base, axis.key, t, axis.values.emplace_back())) return "--vary " + *err;
  }
  return std::nullopt;
}

/// The n-th output of splitmix64 seeded with `seed` (the generator is a counter, so any draw can
/// be computed on its own).
uint64_t splitmix64(uint64_t seed, uint64_t n) {
  uint64_t z = seed + (n + 1) * 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/// The values of sheet `index`, one per axis: the grid's combination (the last axis changing
/// fastest), or a sample (draw index x axes + k of the seed's splitmix64 for axis k, uniform
/// over its list or range).
std::vector<std::string> valuesOf(const Plan& plan, uint64_t index) {
  std::vector<std::string> values(plan.axes.size());
  for (size_t k = plan.axes.size(); k-- > 0;) {
    const Axis& axis = plan.axes[k];
    if (!plan.samples) {
      values[k] = axis.values[index % axis.values.size()];
      index /= axis.values.size();
      continue;
    }
    const double u = double(splitmix64(plan.seed, index * plan.axes.size() + k) >> 11) * 0x1p-53; // [0, 1)
    if (!axis.values.empty()) {
      values[k] = axis.values[std::min(axis.values.size() - 1, size_t(u * double(axis.values.size())))];
    } else if (axis.whole) {
      const double lo = std::min(axis.lo, axis.hi), hi = std::max(axis.lo, axis.hi);
      values[k] = std::to_string(std::llround(std::min(hi, lo + std::floor(u * (hi - lo + 1.0)))));
    } else {
      values[k] = formatNumber(axis.lo + (axis.hi - axis.lo) * u);
    }
  }
  return values;
}

/// One sheet of the sweep: its parameters and its values as JSON (numbers, true/false, names).
struct SweepSheet {
  uint64_t index = 0;
  SimParams params;
  Json values = Json::object();
};

std::optional<std::string> makeSheet(const Plan& plan, uint64_t index, SweepSheet& out) {
  out.index = index;
  out.params = plan.base;
  const auto texts = valuesOf(plan, index);
  for (size_t k = 0; k < plan.axes.size(); ++k)
    if (auto err = applyOverride(out.params, plan.axes[k].key + "=" + texts[k]))
      return "sheet " + std::to_string(index) + ": " + *err;
  for (const Axis& axis : plan.axes) {
    const std::string v = spelledValue(out.params, axis.key);
    if (axis.whole) {
      out.values[axis.key] = std::stoull(v);
    } else if (axis.numeric) {
      double d = 0.0; // the float's shortest decimal, which a double prints back the same
      parseNumber(v, d);
      out.values[axis.key] = d;
    } else if (v == "on" || v == "off") {
      out.values[axis.key] = v == "on";
    } else {
      out.values[axis.key] = v;
    }
  }
  if (auto err = validate(out.params, plan.backend)) return "sheet " + std::to_string(index) + ": " + *err;
  return std::nullopt;
}

/// The indices of this shard's sheets: those equal to the shard modulo the shard count.
std::vector<uint64_t> shardIndices(const Plan& plan) {
  std::vector<uint64_t> out;
  for (uint64_t i = plan.shard; i < plan.sheets; i += plan.shards) out.push_back(i);
  return out;
}

/// Parses the command line's numbers, shard and axes into a plan.
std::optional<std::string> makePlan(const CommonOptions& common, const SweepOptions& o, Plan& plan) {
  plan.base = common.params;
  plan.backend = common.backend;
  if (auto err = parseWhole(o.ticks, 1, kMaxTicks, plan.ticks)) return "--ticks: " + *err;
  if (!o.samples.empty())
    if (auto err = parseWhole(o.samples, 1, kMaxSweepSheets, plan.samples)) return "--samples: " + *err;
  if (!o.seed.empty()) {
    if (o.samples.empty()) return "--seed needs --samples";
    if (auto err = parseWhole(o.seed, 0, UINT64_MAX, plan.seed)) return "--seed: " + *err;
  }
  if (!o.shard.empty()) {
    const auto slash = o.shard.find('/');
    if (slash == std::string::npos) return "--shard '" + o.shard + "': expected i/n (0 <= i < n)";
    if (auto err = parseWhole(o.shard.substr(slash + 1), 1, kMaxSweepSheets, plan.shards)) return "--shard n: " + *err;
    if (auto err = parseWhole(o.shard.substr(0, slash), 0, plan.shards - 1, plan.shard)) return "--shard i: " + *err;
  }
  if (!o.batch.empty())
    if (auto err = parseWhole(o.batch, 1, 65535, plan.batch)) return "--batch: " + *err;
  if (o.vary.empty()) return "--vary: at least one is needed";
  plan.sheets = plan.samples ? plan.samples : 1;
  for (const std::string& arg : o.vary) {
    Axis& axis = plan.axes.emplace_back();
    if (auto err = parseAxis(arg, plan.base, plan.samples > 0, axis)) return err;
    for (size_t k = 0; k + 1 < plan.axes.size(); ++k)
      if (plan.axes[k].key == axis.key) return "--vary " + axis.key + ": varied twice";
    if (!plan.samples && (plan.sheets *= axis.values.size()) > kMaxSweepSheets)
      return "--vary: the grid has more than " + std::to_string(kMaxSweepSheets) + " sheets";
  }
  return std::nullopt;
}

/// Picks the sheets per batch: --batch, or the backend's default, within the memory available (on
/// the GPU, also the device's).
std::optional<std::string> chooseBatch(Plan& plan, uint64_t shard_sheets, int device) {
  const std::string mem_backend = plan.backend == "cpu" ? "cpu" : "gpu";
  const uint64_t per_sheet = std::max<uint64_t>(1, estimateSheetBytes(plan.base, mem_backend));
  uint64_t memory = availableMemoryBytes();
  if (plan.backend != "cpu")
    if (const uint64_t device_bytes = gpuMemoryBytes(device)) memory = std::min(memory, device_bytes);
  const uint64_t budget = memory / 10 * 9, fit = budget / per_sheet;
  if (plan.batch == 0) plan.batch = std::min(plan.backend == "cpu" ? kDefaultCpuBatch : kDefaultGpuBatch, fit);
  plan.batch = std::max<uint64_t>(1, std::min(plan.batch, shard_sheets));
  if (plan.batch > fit)
    return "--batch " + std::to_string(plan.batch) + ": a batch of " + std::to_string(plan.batch) + " " +
           std::to_string(plan.base.cols) + "x" + std::to_string(plan.base.rows) + " sheets needs about " +
           std::to_string((per_sheet * plan.batch) >> 20) + " MiB on the " + mem_backend + " backend; " +
           std::to_string(budget >> 20) + " MiB are available";
  return std::nullopt;
}

/// FNV-1a 64 of a file's bytes, as 16 hex digits; nullopt when it cannot be read.
std::optional<std::string> fileHash(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  uint64_t h = 0xcbf29ce484222325ull;
  for (char c; in.get(c);) h = (h ^ uint8_t(c)) * 0x100000001b3ull;
  return hashHex(h);
}

/// The sweep's definition (sweep.json): everything that decides its sheets' lines, and the shard.
/// The base parameters leave out the keys that change only how fast a sheet runs (the CPU's
/// threads and SIMD kernels), which each machine of a sharded sweep may set as it likes.
Json definition(const SweepOptions& o, const Plan& plan, const std::optional<std::string>& script_hash) {
  Json d;
  d["tender"] = TENDER_VERSION;
  d["preset"] = plan.base.preset;
  Json base = Json::object();
  for (auto& [key, value] : paramValues(plan.base))
    if (key != "threads" && key != "simd") base[key] = value;
  d["base"] = base;
  d["vary"] = o.vary;
  d["samples"] = plan.samples;
  d["seed"] = plan.seed;
  d["script_fnv1a"] = script_hash ? Json(*script_hash) : Json();
  d["ticks"] = plan.ticks;
  d["backend"] = plan.backend;
  d["sheets"] = plan.sheets;
  d["shard"] = std::to_string(plan.shard) + "/" + std::to_string(plan.shards);
  return d;
}

std::string plyName(uint64_t index) {
  char name[40];
  std::snprintf(name, sizeof(name), "sheet_%06llu.ply", static_cast<unsigned long long>(index));
  return name;
}

/// Runs a shard's sheets batch by batch and keeps each one's line (and PLY).
class Runner {
public:
  Runner(const CommonOptions& common, const Plan& plan, const InputScript& script, const std::string& dir, bool ply,
         OutputSet& outputs, Progress& progress)
      : common_(common), plan_(plan), script_(script), dir_(dir), ply_(ply), outputs_(outputs), progress_(progress) {}

  /// Runs every sheet of `indices` in batches of plan.batch.
  std::optional<std::string> run(const std::vector<uint64_t>& indices) {
    std::vector<SweepSheet> pending;
    for (uint64_t index : indices) {
      SweepSheet sheet;
      if (auto err = makeSheet(plan_, index, sheet)) return err;
      pending.push_back(std::move(sheet));
      if (pending.size() == plan_.batch) {
        if (auto err = runBatch(pending)) return err;
        pending.clear();
      }
    }
    if (!pending.empty()) return runBatch(pending);
    return std::nullopt;
  }

  /// The lines, sorted by index.
  std::string lines() {
    std::sort(lines_.begin(), lines_.end());
    std::string text;
    for (auto& [index, line] : lines_) text += line + "\n";
    return text;
  }

private:
  BackendOptions optionsFor(const SimParams& params) const {
    BackendOptions b = backendOptionsFor(plan_.backend, params);
    b.device = common_.device;
    b.validation = common_.validation;
    return b;
  }

  std::optional<std::string> runBatch(const std::vector<SweepSheet>& sheets) {
    std::unique_ptr<SheetBatch> batch;
    if (auto err = createBatch(optionsFor(sheets.front().params), uint32_t(sheets.size()), batch)) return err;
    std::vector<FleetSheet> fleet_sheets;
    for (const SweepSheet& s : sheets) fleet_sheets.push_back({s.params, script_});
    Fleet fleet(*batch, fleet_sheets);
    const auto ms = timedTicks(sheets.size(), [&] {
      fleet.tick();
      batch->finish();
    });
    for (uint32_t i = 0; i < fleet.size(); ++i)
      if (auto err = record(sheets[i], fleet.sim(i), ms, batch->name() == "gpu", fleet.size())) return err;
    return std::nullopt;
  }

  /// Runs `tick` (one tick of `sheets` sheets, finished) the plan's number of times; returns the
  /// wall time of each (ms).
  std::vector<double> timedTicks(uint64_t sheets, const std::function<void()>& tick) {
    std::vector<double> ms;
    for (uint64_t t = 0; t < plan_.ticks; ++t) {
      const auto t0 = std::chrono::steady_clock::now();
      tick();
      ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      progress_.update(done_ += sheets);
    }
    return ms;
  }

  /// The sheet's line: its index, its values, its stats (`tender sim --stats`'s fields) and under
  /// "batch" how its batch ran: the batch's sheets, dispatches, and its median and slowest batched
  /// tick in ms.
  std::optional<std::string> record(const SweepSheet& sheet, Simulation& sim, std::vector<double> ms, bool gpu,
                                    uint32_t batch_sheets) {
    Solver& solver = sim.solver();
    solver.computeNormals();
    SimState state;
    solver.readback(state);
    const SheetStats st = computeStats(state, sim.params().substepDt());
    const nlohmann::json stats =
        runStatsJson(st, solver, {sim.params().preset, plan_.ticks, sim.physicsTicks(), std::move(ms)}, gpu);
    Json line, batch;
    line["index"] = sheet.index;
    line["values"] = sheet.values;
    batch["sheets"] = batch_sheets;
    for (auto& [key, value] : stats.items()) {
      const bool of_batch = std::find(std::begin(kBatchFields), std::end(kBatchFields), key) != std::end(kBatchFields);
      (of_batch ? batch : line)[key] = Json(value);
    }
    line["batch"] = batch;
    lines_.emplace_back(sheet.index, line.dump());
    if (!ply_) return std::nullopt;
    return outputs_.stage(dir_ + plyName(sheet.index), [&](std::FILE* f) { return writePly(f, state); });
  }

  const CommonOptions& common_;
  const Plan& plan_;
  const InputScript& script_;
  std::string dir_;
  bool ply_;
  OutputSet& outputs_;
  Progress& progress_;
  uint64_t done_ = 0;
  std::vector<std::pair<uint64_t, std::string>> lines_;
};

/// The folder of --out with a trailing '/', created when missing.
std::optional<std::string> outputFolder(const std::string& out, std::string& dir) {
  std::error_code ec;
  if (!std::filesystem::is_directory(out, ec)) {
    if (std::filesystem::exists(out, ec)) return "--out '" + out + "' is not a folder";
    std::filesystem::create_directories(out, ec);
    if (ec) return "cannot create '" + out + "': " + ec.message();
  }
  dir = out.back() == '/' ? out : out + "/";
  return std::nullopt;
}

} // namespace

int runSweep(const CommonOptions& common, const SweepOptions& o) {
  Plan plan;
  if (auto err = makePlan(common, o, plan)) return fail(*err);
  const std::vector<uint64_t> indices = shardIndices(plan);
  if (auto err = chooseBatch(plan, indices.size(), common.device)) return fail(*err);
  // Every sheet is checked before anything runs.
  for (uint64_t index : indices) {
    SweepSheet sheet;
    if (auto err = makeSheet(plan, index, sheet)) return fail(*err);
  }
  std::string error;
  auto script = scriptFor(common.script, common.params, error);
  if (!script) return fail(error);
  const auto script_hash = common.script.empty() ? std::nullopt : fileHash(common.script);
  if (!common.script.empty() && !script_hash) return fail("cannot read '" + common.script + "'");

  std::string dir;
  if (auto err = outputFolder(o.out, dir)) return fail(*err);
  OutputSet outputs;
  for (const char* name : {"sheets.jsonl", "sweep.json"})
    if (auto err = outputs.add(dir + name)) return fail(*err);
  if (o.ply)
    for (uint64_t index : indices)
      if (auto err = outputs.add(dir + plyName(index))) return fail(*err);

  const auto start = std::chrono::steady_clock::now();
  Progress progress("tender sweep", "sheet-tick", indices.size() * plan.ticks, 1.0);
  Runner runner(common, plan, *script, dir, o.ply, outputs, progress);
  auto err = runner.run(indices);
  progress.clear();
  if (err) return fail(*err);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  if (auto e = outputs.stage(dir + "sheets.jsonl", runner.lines())) return fail(*e);
  if (auto e = outputs.stage(dir + "sweep.json", definition(o, plan, script_hash).dump(2) + "\n")) return fail(*e);
  if (auto e = outputs.commit()) return fail(*e);
  const double rate = seconds > 0.0 ? double(indices.size() * plan.ticks) / seconds : 0.0;
  std::printf("tender sweep: %zu of %llu sheets (shard %llu/%llu) of %ux%u, %llu ticks on %s in %.1f s: %.0f "
              "sheet-ticks/s; %ssheets.jsonl\n",
              indices.size(), static_cast<unsigned long long>(plan.sheets), static_cast<unsigned long long>(plan.shard),
              static_cast<unsigned long long>(plan.shards), plan.base.cols, plan.base.rows,
              static_cast<unsigned long long>(plan.ticks), plan.backend.c_str(), seconds, rate, dir.c_str());
  return 0;
}

namespace {

/// One shard read back: its definition and its lines by index.
struct ShardFiles {
  std::string dir;
  Json definition;
  std::vector<std::pair<uint64_t, std::string>> lines;
};

std::optional<std::string> readText(const std::string& path, std::string& text) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "cannot read '" + path + "': " + std::strerror(errno);
  std::ostringstream s;
  s << in.rdbuf();
  text = s.str();
  return std::nullopt;
}

std::optional<std::string> loadShard(const std::string& folder, ShardFiles& out) {
  out.dir = folder.back() == '/' ? folder : folder + "/";
  std::string text;
  const std::string def_path = out.dir + "sweep.json", lines_path = out.dir + "sheets.jsonl";
  if (auto err = readText(def_path, text)) return err;
  out.definition = Json::parse(text, nullptr, false);
  if (!out.definition.is_object() || !out.definition.contains("sheets") ||
      !out.definition["sheets"].is_number_unsigned() || out.definition["sheets"].get<uint64_t>() > kMaxSweepSheets ||
      !out.definition.contains("shard"))
    return def_path + ": not a sweep's definition (tender sweep writes it)";
  const uint64_t sheets = out.definition["sheets"].get<uint64_t>();
  if (auto err = readText(lines_path, text)) return err;
  std::istringstream in(text);
  std::string line;
  for (uint64_t n = 1; std::getline(in, line); ++n) {
    if (line.empty()) continue;
    const Json j = Json::parse(line, nullptr, false);
    if (!j.is_object() || !j.contains("index") || !j["index"].is_number_unsigned() ||
        j["index"].get<uint64_t>() >= sheets)
      return lines_path + ": line " + std::to_string(n) +
             ": not a sheet of this sweep (an object with an index below " + std::to_string(sheets) + ")";
    out.lines.emplace_back(j["index"].get<uint64_t>(), line);
  }
  return std::nullopt;
}

/// Why two shards' definitions are not of one sweep (the first field apart from the shard that
/// differs); nullopt when they are.
std::optional<std::string> sweepMismatch(const ShardFiles& a, const ShardFiles& b) {
  for (auto& [key, value] : a.definition.items())
    if (key != "shard" && (!b.definition.contains(key) || b.definition[key] != value))
      return b.dir + " is a shard of another sweep than " + a.dir + " (" + key + " differs)";
  for (auto& [key, value] : b.definition.items())
    if (!a.definition.contains(key))
      return b.dir + " is a shard of another sweep than " + a.dir + " (" + key + " differs)";
  return std::nullopt;
}

/// "3, 7, 12 and 40 more": the first few indices of a list.
std::string someIndices(const std::vector<uint64_t>& v) {
  std::string s;
  for (size_t k = 0; k < std::min<size_t>(v.size(), 10); ++k) s += (k ? ", " : "") + std::to_string(v[k]);
  if (v.size() > 10) s += " and " + std::to_string(v.size() - 10) + " more";
  return s;
}

} // namespace

int runSweepMerge(const SweepMergeOptions& o) {
  if (o.dirs.empty()) return fail("sweep-merge: name the shards' folders");
  std::vector<ShardFiles> shards(o.dirs.size());
  for (size_t k = 0; k < o.dirs.size(); ++k) {
    if (auto err = loadShard(o.dirs[k], shards[k])) return fail(*err);
    if (auto err = sweepMismatch(shards[0], shards[k])) return fail(*err);
  }
  // Every sheet exactly once.
  const uint64_t sheets = shards[0].definition["sheets"].get<uint64_t>();
  std::vector<const std::string*> line_of(sheets, nullptr);
  std::vector<std::string> from(sheets);
  for (const ShardFiles& shard : shards)
    for (auto& [index, line] : shard.lines) {
      if (line_of[index])
        return fail("sheet " + std::to_string(index) + " is doubled (in " + from[index] + " and " + shard.dir + ")");
      line_of[index] = &line;
      from[index] = shard.dir;
    }
  std::vector<uint64_t> missing;
  for (uint64_t i = 0; i < sheets; ++i)
    if (!line_of[i]) missing.push_back(i);
  if (!missing.empty())
    return fail(std::to_string(missing.size()) + " of " + std::to_string(sheets) +
                " sheets are missing: " + someIndices(missing));

  std::string dir;
  if (auto err = outputFolder(o.out, dir)) return fail(*err);
  OutputSet outputs;
  for (const char* name : {"sheets.jsonl", "sweep.json"})
    if (auto err = outputs.add(dir + name)) return fail(*err);
  std::string text;
  for (const std::string* line : line_of) text += *line + "\n";
  Json def = shards[0].definition;
  def["shard"] = "0/1";
  if (auto err = outputs.stage(dir + "sheets.jsonl", text)) return fail(*err);
  if (auto err = outputs.stage(dir + "sweep.json", def.dump(2) + "\n")) return fail(*err);
  if (auto err = outputs.commit()) return fail(*err);
  std::printf("tender sweep-merge: %llu sheets from %zu shards; %ssheets.jsonl\n",
              static_cast<unsigned long long>(sheets), shards.size(), dir.c_str());
  return 0;
}

} // namespace tender
