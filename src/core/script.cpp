#include "script.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>

#include "input_file.h"

namespace tender {
namespace {

bool readToggle(std::istringstream& in, Toggle& t) {
  std::string w;
  if (!(in >> w)) return false;
  if (w == "on")
    t = Toggle::On;
  else if (w == "off")
    t = Toggle::Off;
  else if (w == "toggle")
    t = Toggle::Flip;
  else
    return false;
  return true;
}

// Reads three coordinates; returns an error message (empty when fine).
std::string readVec(std::istringstream& in, glm::vec3& v) {
  for (int k = 0; k < 3; ++k) {
    std::string w;
    if (!(in >> w)) return "missing";
    char* end = nullptr;
    double d = std::strtod(w.c_str(), &end);
    if (end == w.c_str() || *end != 0 || std::isnan(d)) return "'" + w + "' is not a number";
    if (!(std::fabs(d) <= double(kMaxCoordinate)))
      return w + " is out of range [-" + std::to_string(int64_t(kMaxCoordinate)) + ", " +
             std::to_string(int64_t(kMaxCoordinate)) + "]";
    v[k] = float(d);
  }
  return "";
}

// Reads a closure of the hand; returns an error message.
std::optional<std::string> parseClosure(const std::string& w, float& closure) {
  char* end = nullptr;
  const double d = std::strtod(w.c_str(), &end);
  if (end == w.c_str() || *end != 0) return "'" + w + "' is not a number";
  if (auto err = checkClosure(d)) return err;
  closure = float(d);
  return std::nullopt;
}

const char* toggleName(Toggle t) { return t == Toggle::On ? "on" : t == Toggle::Off ? "off" : "toggle"; }

/// The event of a script line after its tick (`verb`, then the rest of the line in `in`) into e; the
/// reason when the line is wrong.
std::optional<std::string> parseScriptEvent(const std::string& verb, std::istringstream& in, ScriptEvent& e) {
  if (verb == "grab") {
    std::string how;
    in >> how;
    if (how == "particle") {
      long long i = -1;
      if (!(in >> i) || i < 0 || i > 0xFFFFFFFELL) return "grab particle needs a particle index";
      e.kind = EventKind::GrabParticle;
      e.particle = uint32_t(i);
    } else if (how == "ray") {
      e.kind = EventKind::GrabRay;
      std::string bad = readVec(in, e.a);
      if (bad.empty()) bad = readVec(in, e.b);
      if (bad == "missing") return "grab ray needs 6 numbers: origin and direction";
      if (!bad.empty()) return "grab ray: " + bad;
      if (glm::dot(e.b, e.b) < 1e-12f) return "grab ray direction is zero";
    } else {
      return "grab needs 'particle <index>' or 'ray <ox oy oz dx dy dz>'";
    }
  } else if (verb == "move") {
    e.kind = EventKind::Move;
    const std::string bad = readVec(in, e.a);
    if (bad == "missing") return "move needs 3 numbers";
    if (!bad.empty()) return "move: " + bad;
  } else if (verb == "release") {
    e.kind = EventKind::Release;
  } else if (verb == "squeeze") {
    e.kind = EventKind::Squeeze;
    std::string word;
    if (!(in >> word)) return "squeeze needs the hand's closure, 0 (open) to 1 (closed)";
    if (auto err = parseClosure(word, e.closure)) return "squeeze: " + *err;
  } else if (verb == "wind" || verb == "pins" || verb == "pause") {
    e.kind = verb == "wind" ? EventKind::Wind : verb == "pins" ? EventKind::Pins : EventKind::Pause;
    if (!readToggle(in, e.toggle)) return verb + " needs on, off or toggle";
  } else if (verb == "reset") {
    e.kind = EventKind::Reset;
  } else if (verb == "set") {
    e.kind = EventKind::Set;
    if (!(in >> e.key >> e.value)) return "set needs a key and a value";
    if (e.key == "preset") {
      if (!presetParams(e.value)) return "set preset: unknown preset '" + e.value + "'";
    } else {
      const auto info = paramInfo(e.key);
      if (!info) return "set: unknown parameter '" + e.key + "'";
      if (info->scope == ParamScope::Solver)
        return "set " + e.key + ": it changes the solver, not the sheet (give it on the command line)";
      SimParams p;
      if (auto err = applyOverride(p, e.key + "=" + e.value)) return "set " + *err;
    }
  } else {
    return "unknown event '" + verb + "'";
  }
  return std::nullopt;
}

} // namespace

std::optional<InputScript> parseScript(const std::string& text, std::string& error) {
  InputScript script;
  std::istringstream lines(text);
  std::string line;
  int number = 0;
  uint64_t last_tick = 0;
  while (std::getline(lines, line)) {
    ++number;
    auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream in(line);
    std::string tick_word, verb;
    if (!(in >> tick_word)) continue; // blank or comment
    auto fail = [&](const std::string& what) {
      error = "line " + std::to_string(number) + ": " + what;
      return std::nullopt;
    };
    uint64_t tick = 0;
    const char* last = tick_word.data() + tick_word.size();
    auto [ptr, ec] = std::from_chars(tick_word.data(), last, tick, 10);
    if (ptr != last || (ec != std::errc() && ec != std::errc::result_out_of_range))
      return fail("expected a tick number, got '" + tick_word + "'");
    if (ec == std::errc::result_out_of_range || tick > kMaxTick)
      return fail("tick " + tick_word + " is out of range [0, " + std::to_string(kMaxTick) + "]");
    if (tick < last_tick) return fail("tick " + tick_word + " comes before an earlier line's tick");
    last_tick = tick;
    if (!(in >> verb)) return fail("missing event after the tick");
    ScriptEvent e;
    e.tick = tick;
    if (auto err = parseScriptEvent(verb, in, e)) return fail(*err);
    std::string extra;
    if (in >> extra) return fail("unexpected '" + extra + "' at the end of the line");
    script.events.push_back(e);
  }
  return script;
}

std::optional<InputScript> loadScript(const std::string& path, std::string& error) {
  std::string text;
  if (auto why = readInputFile(path, kMaxScriptBytes, text)) {
    error = "cannot read script '" + path + "': " + *why;
    return std::nullopt;
  }
  auto s = parseScript(text, error);
  if (!s) error = path + ": " + error;
  return s;
}

std::optional<InputScript> loadScriptFor(const std::string& path, const SimParams& params, const std::string& backend,
                                         std::string& error) {
  auto s = loadScript(path, error);
  if (!s) return s;
  if (auto err = checkScript(*s, params, backend)) {
    error = path + ": " + *err;
    return std::nullopt;
  }
  return s;
}

bool rebuildsSheet(const Settings& settings) {
  for (const auto& kv : settings)
    if (rebuildsSheet(kv.first)) return true;
  return false;
}

size_t takeSettings(const std::vector<ScriptEvent>& events, size_t i, Settings& out) {
  const uint64_t tick = events[i].tick;
  for (; i < events.size() && events[i].kind == EventKind::Set && events[i].tick == tick; ++i)
    out.emplace_back(events[i].key, events[i].value);
  return i;
}

std::optional<std::string> applySettings(SimParams& params, const Settings& settings) {
  SimParams p = params;
  for (const auto& [key, value] : settings) {
    if (key == "preset") {
      if (!presetParams(value)) return "unknown preset '" + value + "'";
      p.preset = value;
    } else if (auto err = applyOverride(p, key + "=" + value)) {
      return err;
    }
  }
  if (auto err = checkRules(p)) return err;
  params = p;
  return std::nullopt;
}

std::optional<std::string> checkScript(const InputScript& script, const SimParams& params, const std::string& backend,
                                       bool fixed_layout) {
  SimParams p = params;
  const auto& events = script.events;
  for (size_t i = 0; i < events.size();) {
    const ScriptEvent& e = events[i];
    const std::string at = "tick " + std::to_string(e.tick) + ": ";
    if (e.kind == EventKind::GrabParticle && e.particle >= p.particleCount())
      return at + "particle " + std::to_string(e.particle) + " does not exist (the sheet has " +
             std::to_string(p.particleCount()) + ")";
    if (e.kind != EventKind::Set) {
      ++i;
      continue;
    }
    Settings settings; // this tick's set events in a row
    i = takeSettings(events, i, settings);
    for (const auto& [key, value] : settings)
      if (fixed_layout && rebuildsSheet(key))
        return at + "set " + key +
               ": the sheets of a fleet keep their layout (set only keys that do not rebuild the sheet)";
    if (auto err = applySettings(p, settings)) return at + "set: " + *err;
    // A sheet the settings rebuild passes the check of `--set`, its memory on the backend included
    if (rebuildsSheet(settings))
      if (auto err = validate(p, backend)) return at + "set: " + *err;
    if (fixed_layout && p.contact_factor > 0.0f && !(params.contact_factor > 0.0f))
      return at + "set contact_factor: the sheets of a fleet keep their layout, and contact's buffers are sized " +
             "when they are made: make the sheet with contact_factor above 0 (a set event may turn it off and on "
             "again)";
  }
  return std::nullopt;
}

std::optional<std::string> checkClosure(double closure) {
  if (std::isnan(closure)) return std::string("the closure is not a number");
  if (closure < 0.0 || closure > 1.0) {
    // the shortest decimal that reads back as this closure: 1.0000001 is not "1"
    char digits[32];
    auto [ptr, ec] = std::to_chars(digits, digits + sizeof(digits), closure);
    return "the closure " + (ec == std::errc() ? std::string(digits, ptr) : std::to_string(closure)) +
           " is out of range [0, 1] (0: open, 1: closed)";
  }
  return std::nullopt;
}

std::string formatEvent(const ScriptEvent& e) {
  std::ostringstream o;
  o.precision(9);
  o << e.tick << ' ';
  switch (e.kind) {
  case EventKind::GrabParticle:
    o << "grab particle " << e.particle;
    break;
  case EventKind::GrabRay:
    o << "grab ray " << e.a.x << ' ' << e.a.y << ' ' << e.a.z << ' ' << e.b.x << ' ' << e.b.y << ' ' << e.b.z;
    break;
  case EventKind::Move:
    o << "move " << e.a.x << ' ' << e.a.y << ' ' << e.a.z;
    break;
  case EventKind::Release:
    o << "release";
    break;
  case EventKind::Squeeze:
    o << "squeeze " << e.closure;
    break;
  case EventKind::Wind:
    o << "wind " << toggleName(e.toggle);
    break;
  case EventKind::Pins:
    o << "pins " << toggleName(e.toggle);
    break;
  case EventKind::Pause:
    o << "pause " << toggleName(e.toggle);
    break;
  case EventKind::Reset:
    o << "reset";
    break;
  case EventKind::Set:
    o << "set " << e.key << ' ' << e.value;
    break;
  }
  return o.str();
}

} // namespace tender
