#include "spirv_rules.h"

#include <algorithm>
#include <unordered_set>

namespace tender::gpu {

namespace {

// SPIR-V numbers (the unified specification, sections 3.x)
constexpr uint32_t kOpCapability = 17, kOpEntryPoint = 15, kOpExecutionMode = 16, kOpExecutionModeId = 331;
constexpr uint32_t kOpDecorate = 71;
constexpr uint32_t kDecorationNoContraction = 42;
constexpr uint32_t kCapDenormPreserve = 4464, kCapDenormFlushToZero = 4465, kCapRoundingModeRTE = 4467;
constexpr uint32_t kModeDenormPreserve = 4459, kModeDenormFlushToZero = 4460, kModeRoundingModeRTE = 4462;

constexpr uint32_t word(uint32_t count, uint32_t op) { return count << 16 | op; }

// Instructions that come before the types, constants and functions in a module (the layout of
// section 2.4): new decorations go right after the last of them.
bool isPreamble(uint32_t op) {
  return op == kOpCapability || op == 10 /*Extension*/ || op == 11 /*ExtInstImport*/ || op == 14 /*MemoryModel*/ ||
         op == kOpEntryPoint || op == kOpExecutionMode || op == kOpExecutionModeId || (op >= 2 && op <= 7) /*debug*/ ||
         op == 330 /*ModuleProcessed*/ || (op >= 71 && op <= 75) /*decorations*/ || op == 332 /*DecorateId*/ ||
         op == 5632 || op == 5633 /*DecorateString, MemberDecorateString*/ || op == 8 || op == 317 /*Line, NoLine*/;
}

} // namespace

FloatRules floatRulesFor(const FloatControls& fc) {
  FloatRules r;
  r.rounding_rte = fc.rounding_rte;
  r.denormals = fc.denorm_preserve ? Denormals::Preserve
                : fc.denorm_flush  ? Denormals::FlushToZero
                                   : Denormals::DeviceDefault;
  return r;
}

const char* denormalsName(Denormals d) {
  switch (d) {
  case Denormals::Preserve:
    return "preserve";
  case Denormals::FlushToZero:
    return "flush to zero";
  case Denormals::DeviceDefault:
    break;
  }
  return "device default";
}

bool isFloatArithmetic(uint32_t op) {
  // OpFNegate, OpFAdd, OpFSub, OpFMul, OpFDiv, OpFRem, OpFMod, OpVectorTimesScalar ... OpDot
  return op == 127 || op == 129 || op == 131 || op == 133 || op == 136 || (op >= 140 && op <= 148);
}

std::vector<uint32_t> applyFloatRules(std::span<const uint32_t> code, const FloatRules& rules) {
  if (code.size() < 5) return {code.begin(), code.end()};
  std::vector<uint32_t> entries, arithmetic;
  std::unordered_set<uint32_t> decorated;
  size_t after_caps = 5, after_modes = 5, preamble_end = 5;
  bool in_preamble = true;
  for (size_t w = 5; w < code.size();) {
    const uint32_t count = code[w] >> 16, op = code[w] & 0xFFFFu;
    if (count == 0 || w + count > code.size()) return {code.begin(), code.end()}; // not ours to fix
    if (op == kOpCapability) after_caps = w + count;
    if (op == kOpEntryPoint && count >= 3) entries.push_back(code[w + 2]);
    if (op == kOpEntryPoint || op == kOpExecutionMode || op == kOpExecutionModeId) after_modes = w + count;
    if (op == kOpDecorate && count >= 3 && code[w + 2] == kDecorationNoContraction) decorated.insert(code[w + 1]);
    if (in_preamble && isPreamble(op))
      preamble_end = w + count;
    else
      in_preamble = false;
    if (isFloatArithmetic(op) && count >= 3) arithmetic.push_back(code[w + 2]);
    w += count;
  }
  std::vector<uint32_t> caps, modes, decorations;
  auto mode = [&](uint32_t cap, uint32_t m) {
    caps.insert(caps.end(), {word(2, kOpCapability), cap});
    for (uint32_t e : entries) modes.insert(modes.end(), {word(4, kOpExecutionMode), e, m, 32u});
  };
  if (rules.rounding_rte) mode(kCapRoundingModeRTE, kModeRoundingModeRTE);
  if (rules.denormals == Denormals::Preserve) mode(kCapDenormPreserve, kModeDenormPreserve);
  if (rules.denormals == Denormals::FlushToZero) mode(kCapDenormFlushToZero, kModeDenormFlushToZero);
  for (uint32_t id : arithmetic)
    if (decorated.insert(id).second)
      decorations.insert(decorations.end(), {word(3, kOpDecorate), id, kDecorationNoContraction});
  // Splice the three runs in at their sections (capabilities < modes < decorations in the module)
  std::vector<uint32_t> out;
  out.reserve(code.size() + caps.size() + modes.size() + decorations.size());
  out.insert(out.end(), code.begin(), code.begin() + long(after_caps));
  out.insert(out.end(), caps.begin(), caps.end());
  out.insert(out.end(), code.begin() + long(after_caps), code.begin() + long(after_modes));
  out.insert(out.end(), modes.begin(), modes.end());
  out.insert(out.end(), code.begin() + long(after_modes), code.begin() + long(preamble_end));
  out.insert(out.end(), decorations.begin(), decorations.end());
  out.insert(out.end(), code.begin() + long(preamble_end), code.end());
  return out;
}

} // namespace tender::gpu
