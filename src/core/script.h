#pragma once
/// Input scripts: timed input events, one per line. Used by tests, `tender sim`, and the demo's
/// record/replay.
///
///   # comment
///   <tick> grab particle <index>
///   <tick> grab ray <ox> <oy> <oz> <dx> <dy> <dz>
///   <tick> move <x> <y> <z>          grab target in world units
///   <tick> release
///   <tick> wind on|off|toggle
///   <tick> pins on|off|toggle
///   <tick> pause on|off|toggle
///   <tick> reset
///
/// Events of tick T apply just before tick T runs (ticks count from 0); lines must be in tick order.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace tender {

/// Largest magnitude of a world coordinate an input may name (script, drag, replay): scripts
/// naming more are refused, and a grab target beyond it is clamped, so the state stays finite.
constexpr float kMaxCoordinate = 1.0e6f;
/// Largest script file (a recorded hour of moves at 60 Hz is about 10 MB).
constexpr uint64_t kMaxScriptBytes = 256ull << 20;
/// Largest tick a script line may name (decimal digits only).
constexpr uint64_t kMaxTick = 1000000000000ull;

enum class EventKind { GrabParticle, GrabRay, Move, Release, Wind, Pins, Pause, Reset };
/// Value of on/off/toggle events.
enum class Toggle { Off, On, Flip };

struct ScriptEvent {
  uint64_t tick = 0;
  EventKind kind = EventKind::Release;
  uint32_t particle = 0; ///< GrabParticle
  glm::vec3 a{0.0f};     ///< GrabRay origin, Move target
  glm::vec3 b{0.0f};     ///< GrabRay direction
  Toggle toggle = Toggle::Flip;
};

/// A parsed script, sorted by tick.
struct InputScript {
  std::vector<ScriptEvent> events;
};

/// Parses script text; on failure returns nullopt and sets `error` to "line N: what".
std::optional<InputScript> parseScript(const std::string& text, std::string& error);
/// Reads and parses a script file; errors name the file.
std::optional<InputScript> loadScript(const std::string& path, std::string& error);
/// Checks a script against a sheet: particle indices must exist. Returns an error message.
std::optional<std::string> checkScript(const InputScript& script, uint32_t particle_count);
/// Reads, parses and checks a script file against a sheet of `particle_count` particles (what
/// every program does with a script it is given); errors name the file.
std::optional<InputScript> loadScriptFor(const std::string& path, uint32_t particle_count, std::string& error);
/// Formats one event as a script line.
std::string formatEvent(const ScriptEvent& e);

} // namespace tender
