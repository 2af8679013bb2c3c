#include "passes.h"

#include <charconv>
#include <vector>

namespace tender {

using namespace shaderio;

namespace {

bool collisionOn(const shaderio::SimUniforms& u) { return (u.flags & SIM_FLAG_COLLISION) != 0u; }

uint32_t perSubstep(const shaderio::SimUniforms& u) {
  return passesPerSubstep(u.iterations, u.color_count, collisionOn(u));
}

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

uint32_t passesPerTick(const shaderio::SimUniforms& u) {
  return u.reset_active ? 1u : substepCount(u.substeps) * perSubstep(u);
}

PassPoint passAt(const shaderio::SimUniforms& u, uint32_t index) {
  PassPoint p;
  if (u.reset_active) {
    p.kind = PassKind::Reset;
    return p;
  }
  const uint32_t per = perSubstep(u), projects = u.iterations * u.color_count;
  p.substep = index / per;
  uint32_t k = index % per;
  if (k == 0) return p;
  if (--k < projects) {
    p.kind = PassKind::Project;
    p.iteration = k / u.color_count;
    p.color = k % u.color_count;
    return p;
  }
  k -= projects;
  if (collisionOn(u) && k-- == 0) {
    p.kind = PassKind::Collide;
    return p;
  }
  p.kind = k == 0 ? PassKind::Floor : PassKind::Tear;
  return p;
}

std::optional<uint32_t> passIndex(const shaderio::SimUniforms& u, const PassPoint& p) {
  if (u.reset_active) return p.kind == PassKind::Reset ? std::optional<uint32_t>(0u) : std::nullopt;
  if (p.substep >= substepCount(u.substeps) || p.kind == PassKind::Reset) return std::nullopt;
  const uint32_t base = p.substep * perSubstep(u), projects = u.iterations * u.color_count;
  const uint32_t collide = collisionOn(u) ? 1u : 0u;
  switch (p.kind) {
  case PassKind::Integrate:
    return base;
  case PassKind::Project:
    if (p.iteration >= u.iterations || p.color >= u.color_count) return std::nullopt;
    return base + 1u + p.iteration * u.color_count + p.color;
  case PassKind::Collide:
    if (!collide) return std::nullopt;
    return base + 1u + projects;
  case PassKind::Floor:
    return base + 1u + projects + collide;
  case PassKind::Tear:
    return base + 2u + projects + collide;
  case PassKind::Reset:
    break;
  }
  return std::nullopt;
}

std::string describePass(const PassPoint& p) {
  switch (p.kind) {
  case PassKind::Reset:
    return "reset";
  case PassKind::Integrate:
    return "substep " + std::to_string(p.substep) + ", integrate";
  case PassKind::Project:
    return "substep " + std::to_string(p.substep) + ", project (iteration " + std::to_string(p.iteration) +
           ", colour " + std::to_string(p.color) + ")";
  case PassKind::Collide:
    return "substep " + std::to_string(p.substep) + ", collide";
  case PassKind::Floor:
    return "substep " + std::to_string(p.substep) + ", floor";
  case PassKind::Tear:
    return "substep " + std::to_string(p.substep) + ", tear";
  }
  return "?";
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
  if (pass.size() == 3 && pass[0] == "project" && parseNumber(pass[1], plant.pass.iteration) &&
      parseNumber(pass[2], plant.pass.color))
    plant.pass.kind = PassKind::Project;
  else if (f[2] == "integrate")
    plant.pass.kind = PassKind::Integrate;
  else if (f[2] == "collide")
    plant.pass.kind = PassKind::Collide;
  else if (f[2] == "floor")
    plant.pass.kind = PassKind::Floor;
  else if (f[2] == "tear")
    plant.pass.kind = PassKind::Tear;
  else {
    error = "planted ULP '" + text + "': unknown pass '" + f[2] + "' (integrate, project.I.C, collide, floor, tear)";
    return std::nullopt;
  }
  return plant;
}

} // namespace tender
