// Shared prelude: lets one header compile as GLSL and as C++.
// In C++ these headers are included inside `namespace shaderio { using namespace glm; }`.
#ifndef SIM_PRELUDE_H
#define SIM_PRELUDE_H
#ifdef __cplusplus
#define SIM_INLINE inline
#define SIM_CONST constexpr
#else
#define SIM_INLINE
#define SIM_CONST const
#endif
#endif
