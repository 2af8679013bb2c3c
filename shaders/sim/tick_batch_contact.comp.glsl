#version 460
// A fleet of small sheets with penetration-free contact: the fleet's fused tick (SIM_BATCH, one
// workgroup per sheet) with contact's bodies, as tick_fused_contact.comp runs them for a sheet alone.
#define SIM_BATCH
#define SIM_FUSED_CONTACT
#include "fused_tick.glsl"
