#pragma once
/// The SIMD kernels of the CPU solver: the projection four (SSE) or eight (AVX, kernels_avx.h)
/// constraints at a time, the tear test four at a time, and the collision gather with a 4-wide
/// distance test. Each gives exactly the bits of the scalar reference: the same IEEE operations in
/// the same order in every lane, and the same order of every sum. The solver runs them unless
/// CpuOptions::simd is off.
#include <cstdint>

#include "shaderio.h"

namespace tender {

struct GatherArrays;

namespace simd {

/// True when this build has the SSE kernels (any x86-64 build); without them the solver runs the
/// scalar reference alone.
#if defined(__SSE2__)
inline constexpr bool kBuilt = true;
#else
inline constexpr bool kBuilt = false;
#endif

/// True when this build has the 8-wide AVX projection and this CPU (and OS) runs it.
bool hasAvx();

/// Projects constraints [begin, end) of one colour four at a time with the operations of
/// solveDistance; `pos` is the vec4 array as floats, the others are the split constraint arrays,
/// `stiffness` is indexed by kind. Returns the first constraint it did not project (end minus the
/// returned value is below 4); the caller projects the rest with solveDistance.
uint32_t project4(float* pos, const uint32_t* a, const uint32_t* b, const float* rest, const uint32_t* kind,
                  const float stiffness[4], uint32_t begin, uint32_t end);
/// The same, eight at a time with AVX; returns `begin` when hasAvx() is false.
uint32_t project8(float* pos, const uint32_t* a, const uint32_t* b, const float* rest, const uint32_t* kind,
                  const float stiffness[4], uint32_t begin, uint32_t end);
/// project8, then project4 on what it leaves.
uint32_t project(float* pos, const uint32_t* a, const uint32_t* b, const float* rest, const uint32_t* kind,
                 const float stiffness[4], uint32_t begin, uint32_t end);

/// The shorten stage on constraints [begin, end) of one colour eight at a time with AVX, with the
/// operations of shortenConstraint (the limit's reach, the tear factor, whether structural edges
/// tear). Returns the first constraint it did not do (`begin` without AVX); the caller does the rest.
uint32_t shorten(float* pos, const uint32_t* a, const uint32_t* b, const float* rest, const uint32_t* kind, float reach,
                 float tear_factor, bool tears, uint32_t begin, uint32_t end);

/// Projects the hinges of slots [begin, end) of one colour eight at a time with AVX, with the
/// operations of projectHinge: `corners` holds each hinge's gridHinge (4 words), `hinge` each slot's hinge,
/// hinges from `first_diagonal` on are diagonals, `alpha` is an edge hinge's compliance over dt^2.
/// Returns the first slot it did not project (`begin` without AVX); the caller projects the rest.
uint32_t projectHinges(float* pos, float* state, const uint32_t* corners, const uint32_t* hinge,
                       uint32_t first_diagonal, float alpha, uint32_t begin, uint32_t end);

/// The creases of hinges [begin, end) eight at a time with AVX, with the operations of creaseHinge:
/// `corners` holds each hinge's gridHinge (4 words), `torn` each hinge's torn flag. Returns the
/// first hinge it did not do (`begin` without AVX).
uint32_t creaseHinges(float* pos, float* state, const uint32_t* corners, const uint32_t* torn, float yield0,
                      float hardening, uint32_t begin, uint32_t end);

/// The length test of shouldTear for constraints [k, k + n), n a multiple of 4 up to 64: bit l is
/// set when constraint k + l is longer than rest x tear_factor, with the same operations.
uint64_t stretched(const float* pos, const uint32_t* a, const uint32_t* b, const float* rest, float tear_factor,
                   uint32_t k, uint32_t n);

/// gatherReference, the same bits: positions tested four at a time, only the neighbour cells that
/// can hold a particle within `search` visited, small adjacency lists tested in registers.
bool gather(const GatherArrays& g, const shaderio::SimUniforms& u, uint32_t begin, uint32_t end, float search,
            bool build);

} // namespace simd
} // namespace tender
