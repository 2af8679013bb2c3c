#pragma once
/// 8-wide AVX kernels of the CPU solver, in their own translation unit built with -mavx and
/// called only when the CPU has AVX. They include nothing with inline functions (no glm, no
/// std containers), so no AVX code can leak into the rest of the program.
#include <cstdint>

namespace tender::avx {

/// True when this build has the AVX kernels and the CPU (and OS) supports AVX.
bool available();

/// Projects the constraints [begin, end) of one colour, eight at a time, with the exact
/// operations of solveDistance; pos is the vec4 array as floats. Returns the first constraint
/// it did not project (the caller finishes the last end - returned < 8).
uint32_t projectColor(float* pos, const uint32_t* a, const uint32_t* b, const float* rest, const uint32_t* kind,
                      const float stiffness[4], uint32_t begin, uint32_t end);

/// The stretch limit as the shorten stage reads it (shortenConstraint).
struct ShortenLimit {
  float reach;       ///< the longest an edge may be (SimUniforms::limit.reach)
  float tear_factor; ///< SimUniforms::tear_factor
  bool tears;        ///< structural edges tear (tearingOn and SimUniforms::tear_kinds)
};

/// The shorten stage on the constraints [begin, end) of one colour, eight at a time, with the
/// exact operations of shortenConstraint (shouldTear, shortenEdge): only the structural ones move.
/// Returns the first constraint it did not do (the caller finishes the last end - returned < 8).
uint32_t shortenColor(float* pos, const uint32_t* a, const uint32_t* b, const float* rest, const uint32_t* kind,
                      const ShortenLimit& limit, uint32_t begin, uint32_t end);

/// One colour of hinges: what the arrays of a hinge slot hold.
struct HingeSlots {
  const uint32_t* corners; ///< 4 per hinge: the edge's ends and its opposite corners (gridHinge)
  const uint32_t* hinge;   ///< per slot: the hinge (its HingeState)
  uint32_t first_diagonal; ///< hinges from here on are diagonals (half the compliance)
  float alpha;             ///< compliance over dt^2 of an edge hinge (SimUniforms::crease.compliance)
};

/// Projects the hinges of slots [begin, end) of one colour, eight at a time, with the exact
/// operations of projectHinge (hingeAngle, simAtan2, solveHinge); `state` is the HingeState array as
/// floats. Returns the first slot it did not project (fewer than 8 are left).
uint32_t projectHinges(float* pos, float* state, const HingeSlots& slots, uint32_t begin, uint32_t end);

/// The creases of hinges [begin, end), eight at a time, with the exact operations of creaseHinge
/// (hingeAngle without the gradient, creaseReturn): `corners` holds each hinge's gridHinge (4
/// words), `torn` each hinge's torn flag. Returns the first hinge it did not do.
uint32_t creaseHinges(float* pos, float* state, const uint32_t* corners, const uint32_t* torn, float yield0,
                      float hardening, uint32_t begin, uint32_t end);

} // namespace tender::avx
