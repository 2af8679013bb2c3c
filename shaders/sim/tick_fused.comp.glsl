#version 460
// Small sheets: a tick (or, on a CPU device, a substep) in one workgroup (fused_tick.glsl).
#include "fused_tick.glsl"
