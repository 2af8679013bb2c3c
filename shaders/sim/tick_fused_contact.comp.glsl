#version 460
// Small sheets with penetration-free contact: the fused tick (fused_tick.glsl) with the contact
// passes' bodies (contact.glsl) at the start of each substep and the bounded step at the floor.
#define SIM_FUSED_CONTACT
#include "fused_tick.glsl"
