#include "stats.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "intersections.h"

namespace tender {

const char* kindName(uint32_t kind) {
  static const char* names[SIM_KIND_COUNT] = {"structural", "shear", "bend", "tri_bend", "hinge"};
  return kind < SIM_KIND_COUNT ? names[kind] : "?";
}

uint64_t fnv1a(const void* data, size_t size, uint64_t h) {
  auto bytes = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) h = (h ^ bytes[i]) * 1099511628211ull;
  return h;
}

uint64_t hashPositions(const std::vector<glm::vec4>& pos) { return fnv1a(pos.data(), pos.size() * sizeof(glm::vec4)); }

SheetStats computeStats(const SimState& s, float substep_dt) {
  SheetStats st;
  st.particles = uint32_t(s.pos.size());
  st.colors = uint32_t(s.colors.size());
  for (uint32_t t : s.torn) st.torn += t ? 1u : 0u;
  st.triangles = s.triangle_count;
  for (const glm::vec4& h : s.hinges) {
    const float deg = std::abs(h.x) * float(180.0 / 3.14159265358979323846);
    st.max_crease_deg = std::max(st.max_crease_deg, deg);
    st.creased += deg > kCreasedDegrees ? 1u : 0u;
  }
  st.state_hash = hashPositions(s.pos);
  st.bbox_min = glm::vec3(INFINITY);
  st.bbox_max = glm::vec3(-INFINITY);
  for (size_t i = 0; i < s.pos.size(); ++i) {
    glm::vec3 p(s.pos[i]);
    bool finite = true;
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(p[k])) ++st.nan_count, finite = false;
    if (!finite) continue;
    st.bbox_min = glm::min(st.bbox_min, p);
    st.bbox_max = glm::max(st.bbox_max, p);
    if (i < s.prev.size()) st.max_speed = std::max(st.max_speed, glm::length(p - glm::vec3(s.prev[i])) / substep_dt);
  }
  for (const ColorRange& r : s.colors)
    for (uint32_t k = r.first; k < r.first + r.count; ++k) {
      const auto& c = s.constraints[k];
      uint32_t kind = c.kind_id & SIM_KIND_MASK;
      st.constraints[kind]++;
      if (kind == SIM_KIND_STRUCTURAL) {
        float len = glm::length(glm::vec3(s.pos[c.b]) - glm::vec3(s.pos[c.a]));
        if (std::isfinite(len)) st.max_stretch = std::max(st.max_stretch, len / c.rest);
      }
    }
  return st;
}

void judgeIntersections(SheetStats& st, const SimState& s) {
  st.pairs = int64_t(intersectingPairs(s.pos, s.triangles, s.triangle_count).pairs);
}

nlohmann::json statsJson(const SheetStats& s) {
  nlohmann::json j;
  j["particles"] = s.particles;
  nlohmann::json cs;
  uint32_t total = 0;
  for (uint32_t k = 0; k < SIM_KIND_COUNT; ++k) cs[kindName(k)] = s.constraints[k], total += s.constraints[k];
  cs["total"] = total;
  j["constraints"] = cs;
  j["colors"] = s.colors;
  j["torn"] = s.torn;
  j["triangles"] = s.triangles;
  j["creased"] = s.creased;
  j["max_crease_deg"] = s.max_crease_deg;
  j["state_hash"] = hashHex(s.state_hash);
  j["bbox_min"] = {s.bbox_min.x, s.bbox_min.y, s.bbox_min.z};
  j["bbox_max"] = {s.bbox_max.x, s.bbox_max.y, s.bbox_max.z};
  j["max_stretch"] = s.max_stretch;
  j["max_speed"] = s.max_speed;
  j["nan_count"] = s.nan_count;
  if (s.pairs >= 0) j["pairs"] = s.pairs;
  return j;
}

std::string hashHex(uint64_t h) {
  char hash[17];
  std::snprintf(hash, sizeof(hash), "%016llx", static_cast<unsigned long long>(h));
  return hash;
}

nlohmann::json runStatsJson(const SheetStats& s, const Solver& solver, RunRecord run, bool gpu, double* median_ms,
                            double* slowest_ms) {
  double median = 0.0, slowest = 0.0;
  std::vector<double>& ms = run.tick_ms;
  if (!ms.empty()) {
    slowest = *std::max_element(ms.begin(), ms.end());
    std::nth_element(ms.begin(), ms.begin() + ms.size() / 2, ms.end());
    median = ms[ms.size() / 2];
  }
  if (median_ms) *median_ms = median;
  if (slowest_ms) *slowest_ms = slowest;
  nlohmann::json j = statsJson(s);
  j["preset"] = run.preset;
  j["backend"] = solver.name();
  j["ticks"] = run.ticks;
  j["physics_ticks"] = run.physics_ticks;
  j["ms_per_tick"] = median;
  j["ms_slowest_tick"] = slowest;
  j["dispatches_per_tick"] = solver.dispatchesPerTick();
  if (solver.contacts() >= 0) j["contacts"] = solver.contacts();
  const Arithmetic arith = solver.arithmetic();
  j["arithmetic"] = {{"rounding", arith.rounding}, {"denormals", arith.denormals}, {"corrected", arith.corrected}};
  j["inexact_math_emulated"] = arith.inexact_math_emulated;
  const PassTimes times = solver.passTimes(); // a GPU's collects its last finished tick once
  nlohmann::json passes = nlohmann::json::object();
  for (auto& [name, t] : times.ms) passes[name] = t;
  if (gpu) j["gpu_ms_per_pass"] = passes;
  if (!times.kernels.empty()) {
    nlohmann::json kernels = nlohmann::json::object();
    for (auto& [name, t] : times.kernels) kernels[name] = t;
    j["gpu_ms_per_kernel"] = kernels;
  }
  return j;
}

bool writePly(std::FILE* f, const SimState& s) {
  const std::string header =
      "ply\nformat binary_little_endian 1.0\ncomment Tender receipt sheet\nelement vertex " +
      std::to_string(s.pos.size()) + "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
      std::to_string(s.triangle_count) + "\nproperty list uchar uint vertex_indices\nend_header\n";
  bool ok = std::fwrite(header.data(), 1, header.size(), f) == header.size();
  for (size_t i = 0; ok && i < s.pos.size(); ++i) ok = std::fwrite(&s.pos[i], 4, 3, f) == 3;
  const unsigned char three = 3;
  for (uint32_t k = 0; ok && k < s.triangle_count; ++k)
    ok = std::fwrite(&three, 1, 1, f) == 1 && std::fwrite(&s.triangles[k], 4, 3, f) == 3;
  return ok;
}

} // namespace tender
