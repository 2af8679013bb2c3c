#include "passes.h"

#include <algorithm>
#include <charconv>
#include <iterator>
#include <string_view>
#include <vector>

namespace tender {

using namespace shaderio;

namespace {

uint32_t perSubstep(const shaderio::SimUniforms& u) {
  return passesPerSubstep(u.iterations, u.color_count, conditionsOf(u));
}

uint32_t stagePassesOf(const shaderio::SimUniforms& u, uint32_t stage) {
  return stagePasses(stage, u.iterations, u.color_count, conditionsOf(u));
}

/// The names of the stages, in SIM_STAGES order.
constexpr const char* kStageNames[] = {
#define TENDER_STAGE_NAME(name, id, repeat, when) #name,
    SIM_STAGES(TENDER_STAGE_NAME)
#undef TENDER_STAGE_NAME
};
static_assert(std::size(kStageNames) == SIM_STAGE_COUNT);
/// Stages numbered once per colour of each iteration (a pass of one names its iteration and colour).
constexpr bool kPerColour[] = {
#define TENDER_STAGE_PER_COLOUR(name, id, repeat, when) SIM_STAGE_REPEATS_##repeat,
    SIM_STAGES(TENDER_STAGE_PER_COLOUR)
#undef TENDER_STAGE_PER_COLOUR
};
bool perColour(PassKind kind) { return kind != PassKind::reset && kPerColour[uint32_t(kind)]; }
#define TENDER_STAGE_ORDER(name, id, repeat, when) static_assert(std::string_view(kStageNames[id]) == #name);
SIM_STAGES(TENDER_STAGE_ORDER)
#undef TENDER_STAGE_ORDER

template <class T>
bool parseNumber(const std::string& s, T& out) {
  const char* end = s.data() + s.size();
  auto [ptr, ec] = std::from_chars(s.data(), end, out);
  return ec == std::errc() && ptr == end && !s.empty();
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> parts(1);
  for (char c : s)
    if (c == sep)
      parts.emplace_back();
    else
      parts.back() += c;
  return parts;
}

} // namespace

uint32_t conditionsOf(const shaderio::SimUniforms& u) {
  return stageConditions(u.flags, u.grab_index, u.hinge.count, u.crease.yield_angle, u.limit.reach, u.contact.radius,
                         u.contact_check.sweeps);
}

uint32_t passesPerTick(const shaderio::SimUniforms& u) {
  return u.reset_active ? 1u : substepCount(u.substeps) * perSubstep(u);
}

PassPoint passAt(const shaderio::SimUniforms& u, uint32_t index) {
  PassPoint p;
  if (u.reset_active) {
    p.kind = PassKind::reset;
    return p;
  }
  p.substep = index / perSubstep(u);
  uint32_t k = index % perSubstep(u);
  for (uint32_t stage = 0; stage < SIM_STAGE_COUNT; ++stage) {
    const uint32_t passes = stagePassesOf(u, stage);
    if (k >= passes) {
      k -= passes;
      continue;
    }
    p.kind = PassKind(stage);
    if (perColour(p.kind)) {
      p.iteration = k / u.color_count;
      p.color = k % u.color_count;
    }
    break;
  }
  return p;
}

std::optional<uint32_t> passIndex(const shaderio::SimUniforms& u, const PassPoint& p) {
  if (u.reset_active) return p.kind == PassKind::reset ? std::optional<uint32_t>(0u) : std::nullopt;
  const uint32_t stage = uint32_t(p.kind);
  if (p.substep >= substepCount(u.substeps) || stage >= SIM_STAGE_COUNT || stagePassesOf(u, stage) == 0)
    return std::nullopt;
  uint32_t within = 0;
  if (perColour(p.kind)) {
    if (p.iteration >= u.iterations || p.color >= u.color_count) return std::nullopt;
    within = p.iteration * u.color_count + p.color;
  }
  return p.substep * perSubstep(u) + stageFirstPass(stage, u.iterations, u.color_count, conditionsOf(u)) + within;
}

std::string describePass(const PassPoint& p) {
  if (p.kind == PassKind::reset) return "reset";
  std::string text = "substep " + std::to_string(p.substep) + ", " + kStageNames[uint32_t(p.kind)];
  if (perColour(p.kind))
    text += " (iteration " + std::to_string(p.iteration) + ", colour " + std::to_string(p.color) + ")";
  return text;
}

std::optional<PlantedUlp> parsePlantedUlp(const std::string& text, std::string& error) {
  const std::vector<std::string> f = split(text, ':');
  PlantedUlp plant;
  if (f.size() != 4 || !parseNumber(f[0], plant.tick) || !parseNumber(f[1], plant.pass.substep) ||
      !parseNumber(f[3], plant.particle)) {
    error = "planted ULP '" + text + "': expected TICK:SUBSTEP:PASS:PARTICLE";
    return std::nullopt;
  }
  const std::vector<std::string> pass = split(f[2], '.');
  const auto named = std::find(std::begin(kStageNames), std::end(kStageNames), pass[0]);
  const bool per_colour = named != std::end(kStageNames) && perColour(PassKind(named - std::begin(kStageNames)));
  if (named == std::end(kStageNames) || pass.size() != (per_colour ? 3u : 1u) ||
      (per_colour && !(parseNumber(pass[1], plant.pass.iteration) && parseNumber(pass[2], plant.pass.color)))) {
    std::string names;
    for (uint32_t stage = 0; stage < SIM_STAGE_COUNT; ++stage)
      names += std::string(stage ? ", " : "") + kStageNames[stage] + (kPerColour[stage] ? ".I.C" : "");
    error = "planted ULP '" + text + "': unknown pass '" + f[2] + "' (" + names + ")";
    return std::nullopt;
  }
  plant.pass.kind = PassKind(named - std::begin(kStageNames));
  return plant;
}

} // namespace tender
