#pragma once
/// C++ view of the GPU structs and per-element maths of the headers beside this one (C++ only:
/// GLSL includes those headers directly).
/// The same headers compile as GLSL; `using namespace glm` makes vec4, dot, length mean the same here.
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>

namespace shaderio {
using namespace glm;
using uint = glm::uint;

/// GLSL's atomicExchange and atomicAdd, for the element bodies (sim_bodies.h) on a word other
/// threads of a parallel loop may touch (relaxed: the end of the loop orders them, as a pipeline
/// barrier does on the GPU).
inline uint atomicExchange(uint& word, uint value) {
  return std::atomic_ref<uint>(word).exchange(value, std::memory_order_relaxed);
}
inline uint atomicAdd(uint& word, uint value) {
  return std::atomic_ref<uint>(word).fetch_add(value, std::memory_order_relaxed);
}

/// An array of words that threads of a parallel loop read while others set them (the torn flags
/// in markUnsupported): `words[i]` reads with a relaxed atomic load and goes to atomicExchange and
/// atomicAdd as a word, so the element bodies read as GLSL and race-free as C++.
struct SharedWords {
  uint* data;
  struct Word {
    uint* p;
    operator uint() const { return std::atomic_ref<uint>(*p).load(std::memory_order_relaxed); }
  };
  Word operator[](uint i) const { return Word{data + i}; }
};
inline uint atomicExchange(SharedWords::Word word, uint value) { return atomicExchange(*word.p, value); }
inline uint atomicAdd(SharedWords::Word word, uint value) { return atomicAdd(*word.p, value); }

#include "sim_types.h"
#include "xpbd.h"

static_assert(sizeof(Constraint) == 16);
static_assert(sizeof(ContactParticle) == 80);
static_assert(sizeof(SimPush) == 16);
static_assert(sizeof(Counters) == 80);
static_assert(sizeof(FusedPush) == 16);
static_assert(sizeof(BatchArgs) == 32);
static_assert(sizeof(AirKeys) == 16 && sizeof(HingeRange) == 16 && sizeof(CreaseKeys) == 16 && sizeof(HandKeys) == 16 &&
              sizeof(HandMotion) == 16 && sizeof(ContactKeys) == 16 && sizeof(ContactChecks) == 16 &&
              sizeof(ContactGrid) == 16 && sizeof(LimitKeys) == 16 && sizeof(VerletKeys) == 16);
static_assert(offsetof(SimUniforms, air) % 16 == 0 && offsetof(SimUniforms, hinge) % 16 == 0 &&
              offsetof(SimUniforms, hand_motion) % 16 == 0 && offsetof(SimUniforms, limit) % 16 == 0 &&
              offsetof(SimUniforms, verlet) % 16 == 0 && offsetof(SimUniforms, wind) % 16 == 0);
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
static_assert(offsetof(SimUniforms, hinge) == 128);
static_assert(offsetof(SimUniforms, hand) == 160);
static_assert(offsetof(SimUniforms, contact) == 192);
static_assert(offsetof(SimUniforms, contact_check) == 208);
static_assert(offsetof(SimUniforms, limit_roots) == 256);
static_assert(offsetof(SimUniforms, wind) == 288);
static_assert(sizeof(SimUniforms) == 288 + 4 * 16 * SIM_MAX_SUBSTEPS);
} // namespace shaderio
