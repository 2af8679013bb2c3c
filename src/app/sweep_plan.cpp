// A sweep's plan: its axes, its sheets' values, its shards and its definition (sweep_plan.h).
#include "sweep_plan.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "core/fleet.h"
#include "core/input_file.h"
#include "core/script.h"
#include "core/stats.h"

namespace tender::sweep {
namespace {

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
  if (s.empty() || ec != std::errc() || ptr != end || std::isnan(out)) return "'" + s + "' is not a number";
  if (std::isinf(out)) return "'" + s + "' is not finite";
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

/// Parses a shard "i/n" (0 <= i < n) into the plan.
std::optional<std::string> parseShard(const std::string& text, Plan& plan) {
  const auto slash = text.find('/');
  if (slash == std::string::npos) return "'" + text + "': expected i/n (0 <= i < n)";
  if (auto err = parseWhole(text.substr(slash + 1), 1, kMaxSweepSheets, plan.shards)) return "n: " + *err;
  if (auto err = parseWhole(text.substr(0, slash), 0, plan.shards - 1, plan.shard)) return "i: " + *err;
  return std::nullopt;
}

/// Parses the plan's --vary arguments into its axes and counts its sheets.
std::optional<std::string> addAxes(Plan& plan) {
  if (plan.vary.empty()) return std::string("--vary: at least one is needed");
  plan.axes.clear();
  plan.sheets = plan.samples ? plan.samples : 1;
  for (const std::string& arg : plan.vary) {
    Axis& axis = plan.axes.emplace_back();
    if (auto err = parseAxis(arg, plan.base, plan.samples > 0, axis)) return err;
    for (size_t k = 0; k + 1 < plan.axes.size(); ++k)
      if (plan.axes[k].key == axis.key) return "--vary " + axis.key + ": varied twice";
    if (!plan.samples && (plan.sheets *= axis.values.size()) > kMaxSweepSheets)
      return "--vary: the grid has more than " + std::to_string(kMaxSweepSheets) + " sheets";
  }
  return std::nullopt;
}

} // namespace

std::optional<std::string> sheetOf(const Plan& plan, uint64_t index, SweepSheet& out) {
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
  return std::nullopt;
}

std::optional<std::string> makeSheet(const Plan& plan, uint64_t index, SweepSheet& out) {
  if (auto err = sheetOf(plan, index, out)) return err;
  if (auto err = validate(out.params, plan.backend)) return "sheet " + std::to_string(index) + ": " + *err;
  return std::nullopt;
}

std::vector<uint64_t> shardIndices(const Plan& plan) {
  std::vector<uint64_t> out;
  for (uint64_t i = plan.shard; i < plan.sheets; i += plan.shards) out.push_back(i);
  return out;
}

uint64_t shardSize(uint64_t sheets, uint64_t shard, uint64_t shards) {
  return shard < sheets ? (sheets - shard + shards - 1) / shards : 0;
}

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
  if (!o.shard.empty())
    if (auto err = parseShard(o.shard, plan)) return "--shard " + *err;
  if (!o.batch.empty())
    if (auto err = parseWhole(o.batch, 1, kMaxBatchSheets, plan.batch)) return "--batch: " + *err;
  plan.vary = o.vary;
  return addAxes(plan);
}

std::optional<std::string> planOfDefinition(const Json& d, Plan& plan) {
  const auto bad = [](const std::string& why) { return "not a sweep's definition (" + why + ")"; };
  const auto whole = [&](const char* key, uint64_t& out) -> bool {
    if (!d.contains(key) || !d[key].is_number_unsigned()) return false;
    out = d[key].get<uint64_t>();
    return true;
  };
  if (!d.is_object()) return bad("not a JSON object");
  if (!d.contains("preset") || !d["preset"].is_string()) return bad("no preset");
  auto base = presetParams(d["preset"].get<std::string>());
  if (!base) return bad("unknown preset");
  if (!d.contains("base") || !d["base"].is_object()) return bad("no base parameters");
  for (auto& [key, value] : d["base"].items()) {
    if (!value.is_string()) return bad("base " + key + " is not a string");
    if (auto err = applyOverride(*base, key + "=" + value.get<std::string>())) return bad("base " + *err);
  }
  plan.base = *base;
  if (!d.contains("backend") || !d["backend"].is_string()) return bad("no backend");
  plan.backend = d["backend"].get<std::string>();
  if (!d.contains("vary") || !d["vary"].is_array()) return bad("no vary");
  plan.vary.clear();
  for (const Json& v : d["vary"]) {
    if (!v.is_string()) return bad("vary holds a non-string");
    plan.vary.push_back(v.get<std::string>());
  }
  uint64_t sheets = 0;
  if (!whole("samples", plan.samples) || !whole("seed", plan.seed) || !whole("ticks", plan.ticks) ||
      !whole("sheets", sheets))
    return bad("samples, seed, ticks and sheets must be whole numbers");
  if (plan.samples > kMaxSweepSheets || plan.ticks < 1 || plan.ticks > kMaxTicks) return bad("out of range");
  if (!d.contains("shard") || !d["shard"].is_string()) return bad("no shard");
  if (auto err = parseShard(d["shard"].get<std::string>(), plan)) return bad("shard " + *err);
  if (auto err = addAxes(plan)) return bad(*err);
  if (plan.sheets != sheets)
    return bad("its vary and samples make " + std::to_string(plan.sheets) + " sheets, not " + std::to_string(sheets));
  return std::nullopt;
}

std::optional<std::string> chooseBatch(Plan& plan, uint64_t shard_sheets, int device) {
  const BatchFit f = batchFit(plan.base, plan.backend, device);
  if (plan.batch == 0) plan.batch = std::min(plan.backend == "cpu" ? kDefaultCpuBatch : kDefaultGpuBatch, f.fit);
  plan.batch = std::max<uint64_t>(1, std::min(plan.batch, shard_sheets));
  if (auto err = batchMemoryError(plan.base, plan.backend, plan.batch, device))
    return "--batch " + std::to_string(plan.batch) + ": " + *err;
  return std::nullopt;
}

std::optional<std::string> fileHash(const std::string& path) {
  std::string text;
  if (readInputFile(path, kMaxScriptBytes, text)) return std::nullopt;
  return hashHex(fnv1a(text.data(), text.size()));
}

// The base parameters leave out the keys that change only how fast a sheet runs (the CPU's
// threads and SIMD kernels), which each machine of a sharded sweep may set as it likes.
Json definition(const Plan& plan, const std::optional<std::string>& script_hash) {
  Json d;
  d["tender"] = TENDER_VERSION;
  d["preset"] = plan.base.preset;
  Json base = Json::object();
  for (auto& [key, value] : paramValues(plan.base))
    if (key != "threads" && key != "simd") base[key] = value;
  d["base"] = base;
  d["vary"] = plan.vary;
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

std::optional<std::string> definitionMismatch(const Json& a, const Json& b) {
  for (auto& [key, value] : a.items())
    if (key != "shard" && (!b.contains(key) || b[key] != value)) return key;
  for (auto& [key, value] : b.items())
    if (!a.contains(key)) return key;
  return std::nullopt;
}

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
} // namespace tender::sweep
