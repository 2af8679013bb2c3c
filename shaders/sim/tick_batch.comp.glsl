#version 460
// A fleet of small sheets: the fused tick of every queued sheet in one dispatch, one workgroup per
// sheet, each reaching its slices of the fleet's buffers by device address (fused_tick.glsl with
// SIM_BATCH; the table in sim_config.h).
#define SIM_BATCH
#include "fused_tick.glsl"
