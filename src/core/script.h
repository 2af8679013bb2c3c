#pragma once
/// Input scripts: timed input events, one per line. Used by tests, `tender sim`, and the demo's
/// record/replay.
///
///   # comment
///   <tick> grab particle <index>
///   <tick> grab ray <ox> <oy> <oz> <dx> <dy> <dz>
///   <tick> move <x> <y> <z>          grab target in world units
///   <tick> release
///   <tick> squeeze <closure>         the hand around the grab: 0 open .. 1 closed (Simulation::squeeze)
///   <tick> wind on|off|toggle
///   <tick> pins on|off|toggle
///   <tick> pause on|off|toggle
///   <tick> reset
///   <tick> set <key> <value>         a parameter, as `--set key=value` (or `set preset <name>`)
///
/// Events of tick T apply just before tick T runs (ticks count from 0); lines must be in tick order.
/// The `set` events of one tick in a row apply together (Simulation::set): keys that rebuild the
/// sheet (rebuildsSheet) rebuild it at rest, the others change the running sheet.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "params.h"

namespace tender {

/// Largest magnitude of a world coordinate an input may name (script, drag, replay): scripts
/// naming more are refused, and a grab target beyond it is clamped, so the state stays finite.
constexpr float kMaxCoordinate = 1.0e6f;
/// Largest script file (a recorded hour of moves at 60 Hz is about 10 MB).
constexpr uint64_t kMaxScriptBytes = 256ull << 20;
/// Largest tick a script line may name (decimal digits only).
constexpr uint64_t kMaxTick = 1000000000000ull;

enum class EventKind { GrabParticle, GrabRay, Move, Release, Squeeze, Wind, Pins, Pause, Reset, Set };
/// Value of on/off/toggle events.
enum class Toggle { Off, On, Flip };

struct ScriptEvent {
  uint64_t tick = 0;
  EventKind kind = EventKind::Release;
  uint32_t particle = 0; ///< GrabParticle
  glm::vec3 a{0.0f};     ///< GrabRay origin, Move target
  glm::vec3 b{0.0f};     ///< GrabRay direction
  float closure = 0.0f;  ///< Squeeze: 0 (open) .. 1 (closed)
  Toggle toggle = Toggle::Flip;
  std::string key, value; ///< Set: a parameter ("preset": the preset's name) and its value as `--set` takes it
};

/// A parsed script, sorted by tick.
struct InputScript {
  std::vector<ScriptEvent> events;
};

/// Parses script text; on failure returns nullopt and sets `error` to "line N: what".
std::optional<InputScript> parseScript(const std::string& text, std::string& error);
/// Reads and parses a script file; errors name the file.
std::optional<InputScript> loadScript(const std::string& path, std::string& error);
/// Checks a script against a sheet of `params` run on `backend` ("cpu" or "gpu", as validate()
/// takes it), following its `set` events: a grabbed particle must exist on the sheet as it is then,
/// each tick's `set` events must give parameters that pass checkRules(), and a sheet they rebuild
/// must fit this machine's memory on the backend (validate(), the check of `--set`). With
/// `fixed_layout` (a fleet's sheets, which share their layout) only keys that do not rebuild the
/// sheet may be set, and contact may not be turned on in a sheet made without it (a fleet sizes
/// contact's buffers when its sheets are made). Returns an error message.
std::optional<std::string> checkScript(const InputScript& script, const SimParams& params, const std::string& backend,
                                       bool fixed_layout = false);
/// Reads, parses and checks a script file against a sheet of `params` on `backend` (what every
/// program does with a script it is given); errors name the file.
std::optional<InputScript> loadScriptFor(const std::string& path, const SimParams& params, const std::string& backend,
                                         std::string& error);
/// `set` assignments applied together: key (or "preset") and value, in order.
using Settings = std::vector<std::pair<std::string, std::string>>;
/// The parameters `params` become with the assignments of one step applied in order; returns the
/// first bad key or value, or the rule the result breaks (checkRules).
std::optional<std::string> applySettings(SimParams& params, const Settings& settings);
/// True when one of the assignments rebuilds the sheet (rebuildsSheet).
bool rebuildsSheet(const Settings& settings);
/// The set events of one tick in a row from `events[i]` (a set event): appends them to `out` and
/// returns the index after them.
size_t takeSettings(const std::vector<ScriptEvent>& events, size_t i, Settings& out);
/// Why `closure` is not a closure of the hand (a number from 0, open, to 1, closed); nullopt when it is.
std::optional<std::string> checkClosure(double closure);
/// Formats one event as a script line.
std::string formatEvent(const ScriptEvent& e);

} // namespace tender
