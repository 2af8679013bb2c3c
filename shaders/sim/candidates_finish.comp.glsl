#version 460
// Collision candidate lists, after a substep's collide pass (one invocation): the lists' state
// for the next substep, and the substep's flags cleared.
// Workgroup size (sim_common.glsl declares it and threadIndex() uses it)
#define SIM_LOCAL_SIZE 1
#define SIM_PUSH_TYPE SimPush
#include "sim_common.glsl"

void main() {
  uvec4 flags = counters.candidate_flags;
  counters.candidate_state = candidatesNextStateOf(
      counters.candidate_state, collideModeOf(counters.candidate_state, flags.x != 0u), flags.y != 0u);
  counters.candidate_flags = uvec4(0u);
}
