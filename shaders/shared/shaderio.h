#pragma once
/// C++ view of the GPU structs and per-element maths of the headers beside this one (C++ only:
/// GLSL includes those headers directly).
/// The same headers compile as GLSL; `using namespace glm` makes vec4, dot, length mean the same here.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>

namespace shaderio {
using namespace glm;
using uint = glm::uint;
#include "sim_types.h"
#include "xpbd.h"

static_assert(sizeof(Constraint) == 16);
static_assert(sizeof(SimPush) == 16);
static_assert(sizeof(Counters) == 80);
static_assert(sizeof(FusedPush) == 16);
static_assert(sizeof(BatchArgs) == 32);
static_assert(sizeof(BatchPush) == 48 && offsetof(BatchPush, batch) == 16);
static_assert(sizeof(BatchPassPush) == 48 && offsetof(BatchPassPush, batch) == 16 &&
              sizeof(ScanPush) == sizeof(SimPush));
static_assert(offsetof(Counters, compact_dispatch) == 16);
static_assert(offsetof(Counters, draw_args) == 32);
static_assert(sizeof(PickResult) == 32);
static_assert(offsetof(PickResult, pos) == 16);
static_assert(offsetof(SimUniforms, stiffness) == 80);
static_assert(offsetof(SimUniforms, grab_index) == 96);
static_assert(offsetof(SimUniforms, air) == 112);
static_assert(offsetof(SimUniforms, wind) == 128);
static_assert(sizeof(SimUniforms) == 128 + 4 * 16 * SIM_MAX_SUBSTEPS);
} // namespace shaderio
