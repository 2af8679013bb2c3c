#version 460
// Contact (contact.glsl), unless the lists are built in this substep: each query with pairs in its
// list (contact_emit named them) against them: the pairs closer than the contact radius lower the
// bounds and push.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE SIM_WG_PARTICLES
#define SIM_PUSH_TYPE SimPush
#include "contact.glsl"
#include "sim_common.glsl"

void main() { contactWalk(threadIndex()); }
