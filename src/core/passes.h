#pragma once
/// The passes of a tick, numbered in the order every solver runs them (the stages of SIM_STAGES,
/// shaders/shared/sim_passes.h): what `tender diff` names when two backends part, and where a tick
/// cut short stops.
#include <cstdint>
#include <optional>
#include <string>

#include "shaderio.h"

namespace tender {

/// A stage of a substep (SIM_STAGES, in its order), or the one pass of a reset frame.
enum class PassKind : uint8_t {
#define TENDER_PASS_KIND(name, id, repeat, when) name = id,
  SIM_STAGES(TENDER_PASS_KIND)
#undef TENDER_PASS_KIND
      reset
};

/// One pass of a tick.
struct PassPoint {
  uint32_t substep = 0;
  PassKind kind = PassKind::integrate;
  uint32_t iteration = 0, color = 0; ///< of a project pass
  bool operator==(const PassPoint&) const = default;
};

/// The conditions a sheet with these uniforms meets (SIM_WHEN_* bits, stageConditions in
/// sim_passes.h): which stages and dispatches of a substep run.
uint32_t conditionsOf(const shaderio::SimUniforms& u);
/// Passes of a tick with these uniforms (a reset frame: its one pass).
uint32_t passesPerTick(const shaderio::SimUniforms& u);
/// The pass at `index` (< passesPerTick(u)) of a tick.
PassPoint passAt(const shaderio::SimUniforms& u, uint32_t index);
/// Index of a pass in a tick with these uniforms; nullopt when the tick has no such pass.
std::optional<uint32_t> passIndex(const shaderio::SimUniforms& u, const PassPoint& p);
/// "substep 3, project (iteration 2, colour 5)".
std::string describePass(const PassPoint& p);

/// A one-ULP change planted in one particle's position after one pass of one tick: the test hook
/// that proves `tender diff` finds a divergence where it happens.
struct PlantedUlp {
  uint64_t tick = 0;     ///< the solver's tick, counted from 0 at upload
  PassPoint pass;        ///< after this pass
  uint32_t particle = 0; ///< its x coordinate moves to the next float up
};
/// Parses "TICK:SUBSTEP:PASS:PARTICLE", PASS a stage's name (project.I.C: iteration I, colour C);
/// nullopt and one line in `error` when malformed.
std::optional<PlantedUlp> parsePlantedUlp(const std::string& text, std::string& error);

} // namespace tender
