// exact_math.h with its three switches as specialization constants (see sim_config.h).
#ifndef SIM_EXACT_MATH_GLSL
#define SIM_EXACT_MATH_GLSL
#include "sim_config.h"
layout(constant_id = SIM_SPEC_INEXACT_MATH) const bool kInexactMath = false;
layout(constant_id = SIM_SPEC_CORRECT_MATH) const bool kCorrectMath = true;
layout(constant_id = SIM_SPEC_FLUSH_DENORMALS) const bool kFlushDenormals = false;
#define SIM_INEXACT_MATH kInexactMath
#define SIM_CORRECT_MATH kCorrectMath
#define SIM_FLUSH_DENORMALS kFlushDenormals
#include "exact_math.h"
#endif
