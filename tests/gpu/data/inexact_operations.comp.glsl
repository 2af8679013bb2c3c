#version 460
// A simulation shader that asks the device for results it may round its own way: a divide and a
// square root outside exact_math.h's correction. tender-spirv-rules refuses it (spirv.inexact_rule).
#define SIM_INLINE
#include "exact_math.h"
layout(local_size_x = 1) in;
layout(std430, binding = 0) buffer Data { float v[]; };

float share(float a, float b) { return a / b; }
float root(float x) { return deviceSqrt(x); }

void main() { v[0] = share(v[1], v[2]) + root(v[3]) + simDiv(v[4], v[5]) + simSqrt(v[6]); }
