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

} // namespace tender::avx
