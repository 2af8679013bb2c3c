#include "params.h"

#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "sim_config.h"

namespace tender {
namespace {

std::string fmt(float v) {
  char buf[32];
  snprintf(buf, sizeof(buf), "%g", double(v));
  return buf;
}

struct Param {
  ParamInfo info;
  std::function<std::optional<std::string>(SimParams&, const std::string&)> set;
  std::function<std::string(const SimParams&)> get; ///< the value, spelled as `set` takes it
};

// The shortest decimal that reads back as the same float.
std::string shortest(float v) {
  char buf[64];
  auto [ptr, ec] = std::to_chars(buf, buf + sizeof(buf), v);
  return ec == std::errc() ? std::string(buf, ptr) : fmt(v);
}

std::optional<std::string> parseFloat(const std::string& s, float lo, float hi, float& out) {
  float v = 0.0f;
  const char* end = s.data() + s.size();
  auto [ptr, ec] = std::from_chars(s.data(), end, v);
  if (s.empty() || ec != std::errc() || ptr != end || std::isnan(v)) return "'" + s + "' is not a number";
  if (std::isinf(v)) return "'" + s + "' is not finite";
  if (v < lo || v > hi) {
    char buf[128];
    snprintf(buf, sizeof(buf), "%s is out of range [%g, %g]", s.c_str(), double(lo), double(hi));
    return std::string(buf);
  }
  out = v;
  return std::nullopt;
}

std::optional<std::string> parseUint(const std::string& s, uint32_t lo, uint32_t hi, uint32_t& out) {
  uint64_t v = 0;
  if (auto err = parseWhole(s, lo, hi, v)) return err;
  out = uint32_t(v);
  return std::nullopt;
}

std::optional<std::string> parseBool(const std::string& s, bool& out) {
  if (s == "on" || s == "true" || s == "1") return out = true, std::nullopt;
  if (s == "off" || s == "false" || s == "0") return out = false, std::nullopt;
  return "'" + s + "' is not on/off";
}

// A particle's grid place packs its row and column in 16 bits each (sim_elements.glsl).
static_assert(kMaxSide < (1u << 16));

Param floatParam(const char* key, float SimParams::*m, float lo, float hi, const char* help) {
  return {{key, help, lo, hi},
          [m, lo, hi](SimParams& p, const std::string& v) { return parseFloat(v, lo, hi, p.*m); },
          [m](const SimParams& p) { return shortest(p.*m); }};
}
Param uintParam(const char* key, uint32_t SimParams::*m, uint32_t lo, uint32_t hi, const char* help) {
  return {{key, help, double(lo), double(hi), true},
          [m, lo, hi](SimParams& p, const std::string& v) { return parseUint(v, lo, hi, p.*m); },
          [m](const SimParams& p) { return std::to_string(p.*m); }};
}
Param boolParam(const char* key, bool SimParams::*m, const char* help) {
  return {{key, help, 0.0, 0.0, false, true},
          [m](SimParams& p, const std::string& v) { return parseBool(v, p.*m); },
          [m](const SimParams& p) { return std::string(p.*m ? "on" : "off"); }};
}
/// A float key that is 0 (off) or in [lo, hi] (on): a value between 0 and lo is neither. Its help
/// ends with the range, from the same bounds.
Param offOrRange(const char* key, float SimParams::*m, float lo, float hi, const char* help) {
  Param p = floatParam(key, m, 0.0f, hi, help);
  p.info.help += " (0: off, else " + fmt(lo) + " to " + fmt(hi) + ")";
  p.info.least_on = lo;
  p.set = [m, lo, hi](SimParams& s, const std::string& v) -> std::optional<std::string> {
    float f = 0.0f;
    if (auto err = parseFloat(v, 0.0f, hi, f)) return err;
    if (f > 0.0f && f < lo) return v + " is neither 0 (off) nor at least " + fmt(lo);
    s.*m = f;
    return std::nullopt;
  };
  return p;
}
/// `p` with the scope of its changes.
Param scoped(Param p, ParamScope scope) {
  p.info.scope = scope;
  return p;
}
template <typename E>
Param enumParam(const char* key, E SimParams::*m, std::vector<std::pair<std::string, E>> names, const char* help) {
  return {{key, help},
          [m, names](SimParams& p, const std::string& v) -> std::optional<std::string> {
            std::string all;
            for (auto& [n, e] : names) {
              if (n == v) return p.*m = e, std::nullopt;
              all += (all.empty() ? "" : ", ") + n;
            }
            return "'" + v + "' is not one of " + all;
          },
          [m, names](const SimParams& p) {
            for (auto& [n, e] : names)
              if (p.*m == e) return n;
            return std::string();
          }};
}

const std::vector<Param>& params() {
  static const std::vector<Param> table = {
      scoped(uintParam("cols", &SimParams::cols, 1, kMaxSide, "particles across"), ParamScope::Topology),
      scoped(uintParam("rows", &SimParams::rows, 1, kMaxSide, "particles down"), ParamScope::Topology),
      scoped(floatParam("spacing", &SimParams::spacing, 1e-3f, 10.0f, "rest distance between neighbours"),
             ParamScope::Topology),
      scoped(enumParam("pins", &SimParams::pins,
                       {{"top3", PinMode::Top3}, {"corners", PinMode::Corners}, {"none", PinMode::None}},
                       "pinned particles: top3, corners, none"),
             ParamScope::Sheet),
      scoped(floatParam("top_y", &SimParams::top_y, -1000.0f, 1000.0f, "y of the top edge (0: centre on y = 1)"),
             ParamScope::Sheet),
      scoped(floatParam("tilt", &SimParams::tilt, 0.0f, 90.0f, "degrees the sheet leans back from hanging (90: flat)"),
             ParamScope::Sheet),
      floatParam("view_scale", &SimParams::view_scale, 1e-3f, 1e3f,
                 "size of the scene the ground covers (1: the tender sheet's; at any other, the camera frames the "
                 "sheet and follows it)"),
      scoped(boolParam("shear", &SimParams::shear, "diagonal constraints"), ParamScope::Topology),
      scoped(boolParam("bend", &SimParams::bend, "skip-one bend constraints"), ParamScope::Topology),
      scoped(boolParam("tri_bend", &SimParams::tri_bend, "bending across adjacent triangles"), ParamScope::Topology),
      scoped(boolParam("dihedral", &SimParams::dihedral,
                       "signed dihedral bending of every hinge (XPBD, bending_rigidity; creases)"),
             ParamScope::Topology),
      floatParam("tick_hz", &SimParams::tick_hz, 1.0f, 10000.0f, "fixed ticks per second"),
      uintParam("substeps", &SimParams::substeps, 1, SIM_MAX_SUBSTEPS, "substeps per tick"),
      uintParam("iterations", &SimParams::iterations, 1, 256, "constraint iterations per substep"),
      floatParam("max_frame_dt", &SimParams::max_frame_dt, 1e-3f, 1.0f, "frame dt clamp (s)"),
      floatParam("gravity", &SimParams::gravity, 0.0f, 1000.0f, "gravity magnitude, pointing -Y"),
      floatParam("damping", &SimParams::damping, 0.0f, 1.0f, "velocity factor per substep"),
      boolParam("wind", &SimParams::wind, "wind on at start"),
      enumParam("wind_kind", &SimParams::wind_kind, {{"sinusoid", WindKind::Sinusoid}, {"noise", WindKind::Noise}},
                "wind model: sinusoid, noise"),
      floatParam("wind_strength", &SimParams::wind_strength, 0.0f, 100.0f, "wind multiplier"),
      floatParam("wind_scale", &SimParams::wind_scale, 0.0f, 1000.0f, "wind acceleration at strength 1"),
      boolParam("air", &SimParams::air, "air drag and lift on each triangle (SI units)"),
      floatParam("air_density", &SimParams::air_density, 0.0f, 100.0f, "air density (kg/m^3)"),
      floatParam("paper_weight", &SimParams::paper_weight, 1.0f, 10000.0f, "paper weight (g/m^2)"),
      floatParam("drag_coefficient", &SimParams::drag_coefficient, 0.0f, 10.0f, "air pressure drag along the normal"),
      floatParam("skin_friction", &SimParams::skin_friction, 0.0f, 1.0f, "air friction along the sheet"),
      floatParam("stiffness", &SimParams::stiffness, 0.0f, 1.0f, "structural and shear stiffness"),
      floatParam("bend_stiffness", &SimParams::bend_stiffness, 0.0f, 1.0f, "bend stiffness"),
      floatParam("bending_rigidity", &SimParams::bending_rigidity, 1e-12f, 1e6f,
                 "bending rigidity of the hinges (N m; dihedral)"),
      floatParam("crease_yield", &SimParams::crease_yield, 0.0f, 180.0f,
                 "degrees a hinge bends past its rest angle before it creases (0: elastic)"),
      floatParam("crease_hardening", &SimParams::crease_hardening, 0.0f, 1000.0f,
                 "yield a crease adds per radian it moves the rest angle"),
      offOrRange("stretch_limit", &SimParams::stretch_limit, 1.0f, 10.0f,
                 "longest a structural edge may be after each substep, x rest"),
      floatParam("tear_factor", &SimParams::tear_factor, 0.0f, 100.0f, "tear beyond factor x rest; 0: never"),
      boolParam("tear_structural", &SimParams::tear_structural, "structural constraints may tear"),
      boolParam("tear_shear", &SimParams::tear_shear, "shear constraints may tear"),
      boolParam("tear_bend", &SimParams::tear_bend, "bend constraints may tear"),
      boolParam("collision", &SimParams::collision, "self-collision"),
      floatParam("cell_size", &SimParams::cell_size, 1e-3f, 100.0f, "spatial hash cell size"),
      floatParam("collision_factor", &SimParams::collision_factor, 0.0f, 10.0f,
                 "repulsion radius as a multiple of spacing"),
      floatParam("collision_stiffness", &SimParams::collision_stiffness, 0.0f, 1.0f, "repulsion strength"),
      offOrRange("contact_factor", &SimParams::contact_factor, kMinContactFactor, kMaxContactFactor,
                 "penetration-free contact radius as a multiple of spacing"),
      uintParam("contact_settle", &SimParams::contact_settle, 0, SIM_SETTLE_MAX_SWEEPS,
                "sweeps a substep that shorten edges the contact held past the stretch limit (0: none)"),
      floatParam("floor_y", &SimParams::floor_y, -1e4f, 1e4f, "ground height"),
      floatParam("restitution", &SimParams::restitution, 0.0f, 1.0f, "bounce off the ground"),
      floatParam("friction", &SimParams::friction, 0.0f, 1.0f, "ground friction"),
      enumParam("release", &SimParams::release,
                {{"zero", ReleaseMode::ZeroVelocity}, {"drag", ReleaseMode::DragVelocity}},
                "velocity on release: zero, drag"),
      floatParam("grab_radius", &SimParams::grab_radius, 0.0f, 100.0f, "pick radius around the ray"),
      floatParam("hand_reach", &SimParams::hand_reach, 0.0f, 1000.0f,
                 "how far around the grab a closing hand draws the sheet in"),
      scoped(uintParam("threads", &SimParams::threads, 0, 255, "CPU solver threads, 0: one per core (same results)"),
             ParamScope::Solver),
      scoped(boolParam("simd", &SimParams::simd,
                       "CPU solver SIMD kernels; off: the plain scalar reference (same results)"),
             ParamScope::Solver),
  };
  return table;
}

} // namespace

std::optional<std::string> parseWhole(const std::string& s, uint64_t lo, uint64_t hi, uint64_t& out) {
  uint64_t v = 0;
  const char* end = s.data() + s.size();
  auto [ptr, ec] = std::from_chars(s.data(), end, v, 10);
  if (s.empty() || ptr != end || (ec != std::errc() && ec != std::errc::result_out_of_range))
    return "'" + s + "' is not a whole number";
  if (ec == std::errc::result_out_of_range || v < lo || v > hi)
    return s + " is out of range [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  out = v;
  return std::nullopt;
}

std::vector<std::string> presetNames() {
  std::vector<std::string> names;
  for (const BuiltinPreset& preset : builtinPresets()) names.push_back(preset.name);
  return names;
}

std::string unknownPreset(const std::string& name) {
  std::string names;
  for (const std::string& n : presetNames()) names += (names.empty() ? "" : ", ") + n;
  return "unknown preset '" + name + "' (one of " + names + ")";
}

float SimParams::airPressureFactor() const {
  return air_density * drag_coefficient / (2.0f * (paper_weight * 1e-3f) * spacing * spacing);
}

float SimParams::hingeCompliance() const {
  const double dt = 1.0 / (double(tick_hz) * substeps);
  return float(double(paper_weight) * 1e-3 * double(spacing) * spacing / (3.0 * double(bending_rigidity) * dt * dt));
}

float SimParams::airFrictionFactor() const {
  return air_density * skin_friction / (2.0f * (paper_weight * 1e-3f) * spacing * spacing);
}

float SimParams::handBallRadius() const {
  const double area = double(cols > 1 ? cols - 1 : 1) * double(rows > 1 ? rows - 1 : 1) * spacing * spacing;
  const double volume = area * collisionRadius() / kHandPacking;
  return float(std::cbrt(volume * 3.0 / (4.0 * 3.14159265358979323846)));
}

std::optional<SimParams> presetParams(const std::string& name) {
  for (const BuiltinPreset& preset : builtinPresets()) {
    if (name != preset.name) continue;
    SimParams p; // a built-in file that names no preset starts from the defaults
    if (auto err = applyPresetText(preset.json, "preset " + name, std::nullopt, p))
      throw std::logic_error("the built-in " + *err); // the build's own data: the tests read every one
    p.preset = name;
    return p;
  }
  return std::nullopt;
}

const std::vector<ParamInfo>& paramKeys() {
  static const std::vector<ParamInfo> keys = [] {
    std::vector<ParamInfo> k;
    for (auto& p : params()) k.push_back(p.info);
    return k;
  }();
  return keys;
}

std::optional<std::string> applyOverride(SimParams& p, const std::string& assignment) {
  auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) return "expected key=value, got '" + assignment + "'";
  std::string key = assignment.substr(0, eq), value = assignment.substr(eq + 1);
  for (auto& param : params())
    if (param.info.key == key) {
      if (auto err = param.set(p, value)) return key + ": " + *err;
      return std::nullopt;
    }
  return "unknown parameter '" + key + "' (see --help for the keys)";
}

bool rebuildsSheet(const std::string& key) {
  const auto info = paramInfo(key);
  return info && (info->scope == ParamScope::Sheet || info->scope == ParamScope::Topology);
}

std::optional<ParamInfo> paramInfo(const std::string& key) {
  for (auto& param : params())
    if (param.info.key == key) return param.info;
  return std::nullopt;
}

std::vector<std::pair<std::string, std::string>> paramValues(const SimParams& p) {
  std::vector<std::pair<std::string, std::string>> values;
  for (auto& param : params()) values.emplace_back(param.info.key, param.get(p));
  return values;
}

std::string presetJson(const SimParams& p) {
  // Keys in the order of paramKeys(), after "preset".
  nlohmann::ordered_json j;
  j["preset"] = p.preset;
  for (auto& param : params()) {
    const std::string v = param.get(p);
    if (param.info.lo == param.info.hi) {
      if (v == "on" || v == "off")
        j[param.info.key] = v == "on";
      else
        j[param.info.key] = v;
    } else if (param.info.whole) {
      j[param.info.key] = std::stoull(v);
    } else {
      // The float's shortest decimal as a double prints as the same digits.
      double d = 0.0;
      std::from_chars(v.data(), v.data() + v.size(), d);
      j[param.info.key] = d;
    }
  }
  return j.dump(2) + "\n";
}

SheetCounts sheetCounts(const SimParams& p) {
  const uint64_t w = p.cols, h = p.rows;
  auto pairs = [](uint64_t a, uint64_t b) { return a > b ? a - b : 0; }; // a - b, at least 0
  SheetCounts c;
  c.particles = w * h;
  c.constraints = pairs(w, 1) * h + w * pairs(h, 1);
  if (p.shear) c.constraints += (p.dihedral ? 1 : 2) * pairs(w, 1) * pairs(h, 1);
  if (p.bend) c.constraints += pairs(w, 2) * h + w * pairs(h, 2);
  if (p.tri_bend) c.constraints += pairs(w, 1) * pairs(h, 2) + pairs(w, 2) * pairs(h, 1);
  if (p.dihedral && w > 1 && h > 1) {
    c.hinges = pairs(w, 1) * pairs(h, 2) + pairs(w, 2) * pairs(h, 1) + pairs(w, 1) * pairs(h, 1);
    c.constraints += c.hinges;
  }
  c.triangles = 2 * pairs(w, 1) * pairs(h, 1);
  c.hash_buckets = 2;
  while (c.hash_buckets < 2 * c.particles) c.hash_buckets <<= 1;
  return c;
}

uint64_t estimateSheetBytes(const SimParams& p, const std::string& backend) {
  const SheetCounts c = sheetCounts(p);
  const uint64_t n = c.particles, m = c.constraints, t = c.triangles, hb = c.hash_buckets, hinges = c.hinges;
  // SheetTopology: rest, uv, constraints, adjacency (offsets and 2 entries per constraint),
  // triangles and their edges.
  const uint64_t topology = 24 * n + 16 * m + 4 * n + 8 * m + 24 * t;
  // Building it: colour masks, colours, the sorted copy, the edge ids of the triangles.
  const uint64_t building = 8 * n + 20 * m + 8 * n;
  // The read-back state: pos, prev, normal, constraints, torn flags, triangles.
  const uint64_t state = 48 * n + 20 * m + 16 * t + 16 * hinges;
  uint64_t solver = 0;
  if (backend == "cpu") {
    // Particle arrays (pos, prev, rest, normal, delta, reset source, uv), constraints with their
    // split copy (and the hinges' corners) and torn flags, triangles, adjacency, the hash and its sorted copies, the
    // collision candidate lists.
    solver = 104 * n + 40 * m + 16 * t + 4 * n + 8 * m + 8 * hb + 28 * n + 28 * n + 76 * n;
    solver += 4 * m + 16 * hinges; // each slot's hinge, each hinge's corners
  } else {
    // The solver's copy of the topology, its storage buffers (particle arrays, constraints and
    // their compaction scratch, hash, candidate lists) and the largest staging of an upload.
    // (and what a driver keeping device memory on the host adds: ~80 bytes per particle).
    solver =
        80 * n + topology + 16 * 9 * n + 4 * 6 * n + 36 * m + 48 * t + 12 * hb + 80 * n + 4 * (m + t) + 72 * n + 16 * m;
  }
  return topology + std::max(building, state) + solver + 16 * hinges; // the solver's hinge states
}

uint64_t availableMemoryBytes() {
  if (std::FILE* f = std::fopen("/proc/meminfo", "r")) {
    char line[256];
    unsigned long long kb = 0;
    bool found = false;
    while (!found && std::fgets(line, sizeof(line), f)) found = std::sscanf(line, "MemAvailable: %llu kB", &kb) == 1;
    std::fclose(f);
    if (found) return uint64_t(kb) * 1024;
  }
  long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? uint64_t(pages) * uint64_t(page) / 2 : ~uint64_t(0);
}

std::optional<std::string> checkRules(const SimParams& p) {
  uint64_t n = uint64_t(p.cols) * p.rows;
  if (n == 0) return "the grid has no particles";
  if (n > kMaxParticles)
    return "a grid of " + std::to_string(n) + " particles is too large (at most " + std::to_string(kMaxParticles) + ")";
  if (p.substeps > SIM_MAX_SUBSTEPS) return "substeps is at most " + std::to_string(SIM_MAX_SUBSTEPS);
  if (p.collision && p.collisionRadius() > p.cell_size)
    return "collision radius (" + fmt(p.collisionRadius()) + ") must not exceed cell_size (" + fmt(p.cell_size) + ")";
  return std::nullopt;
}

uint64_t memoryBudget(uint64_t available) { return available / 10 * 9; }

std::optional<std::string> validate(const SimParams& p, const std::string& backend) {
  if (auto err = checkRules(p)) return err;
  // Refused up front, with room to spare (a tenth of the memory for everything else).
  const uint64_t need = estimateSheetBytes(p, backend), have = availableMemoryBytes();
  if (need > memoryBudget(have))
    return "a " + std::to_string(p.cols) + "x" + std::to_string(p.rows) + " sheet needs about " +
           std::to_string(need >> 20) + " MiB on the " + (backend == "cpu" ? "cpu" : "gpu") + " backend; " +
           std::to_string(have >> 20) + " MiB are available";
  return std::nullopt;
}

} // namespace tender
