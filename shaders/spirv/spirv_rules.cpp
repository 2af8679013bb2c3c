#include "spirv_rules.h"

#include <algorithm>
#include <cstring>
#include <string_view>
#include <unordered_map>
#include <unordered_set>

namespace tender::gpu {

namespace {

// SPIR-V numbers (the unified specification, sections 3.x)
constexpr uint32_t kOpCapability = 17, kOpEntryPoint = 15, kOpExecutionMode = 16, kOpExecutionModeId = 331;
constexpr uint32_t kOpDecorate = 71;
constexpr uint32_t kDecorationNoContraction = 42;
constexpr uint32_t kCapDenormFlushToZero = 4465, kCapRoundingModeRTE = 4467;
constexpr uint32_t kModeDenormFlushToZero = 4460, kModeRoundingModeRTE = 4462;

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
  r.denormals = fc.denorm_flush ? Denormals::FlushToZero : Denormals::FlushInShader;
  return r;
}

const char* denormalsName(Denormals d) {
  switch (d) {
  case Denormals::FlushToZero:
    return "flush to zero (device)";
  case Denormals::FlushInShader:
    return "flush to zero (shader)";
  case Denormals::FlushByHost:
    return "flush to zero (the host's FTZ and DAZ)";
  case Denormals::AsWritten:
    break;
  }
  return "as written";
}

bool isFloatArithmetic(uint32_t op) {
  // OpFNegate, OpFAdd, OpFSub, OpFMul, OpFDiv, OpFRem, OpFMod, OpVectorTimesScalar ... OpDot
  return op == 127 || op == 129 || op == 131 || op == 133 || op == 136 || (op >= 140 && op <= 148);
}

namespace {

/// The float arithmetic whose result can be a denormal when its operands are not (OpFNegate, a
/// sign flip, cannot; the matrix products are not used by the shaders and are left alone).
bool canMakeDenormal(uint32_t op) {
  return op == 129 || op == 131 || op == 133 || op == 136 || op == 140 || op == 141 || op == 142 || op == 148;
}

/// The types and constants a module's flushes need, found among its own declarations or added
/// (a module may not declare a scalar or vector type twice).
struct FlushTypes {
  uint32_t bound = 0;
  uint32_t f32 = 0, u32 = 0, boolean = 0;
  uint32_t vec_f[5] = {}, vec_u[5] = {}, vec_b[5] = {};
  std::vector<uint32_t> declarations; // added before the first function
  // per component count (1: scalar): the uint type, bool type, and the constants exponent mask,
  // sign mask and zero
  struct Width {
    uint32_t uint_type = 0, bool_type = 0, exponent = 0, sign = 0, zero = 0;
  } widths[5];

  uint32_t fresh() { return bound++; }

  /// The component count of float type `type` (1 for the scalar), or 0 when it is not one.
  uint32_t floatWidth(uint32_t type) const {
    if (type != 0 && type == f32) return 1;
    for (uint32_t n = 2; n <= 4; ++n)
      if (type != 0 && type == vec_f[n]) return n;
    return 0;
  }

  const Width& width(uint32_t n) {
    Width& w = widths[n];
    if (w.uint_type) return w;
    if (!u32) {
      u32 = fresh();
      declarations.insert(declarations.end(), {word(4, 21 /*TypeInt*/), u32, 32u, 0u});
    }
    if (!boolean) {
      boolean = fresh();
      declarations.insert(declarations.end(), {word(2, 20 /*TypeBool*/), boolean});
    }
    const uint32_t scalar[3] = {0x7F800000u, 0x80000000u, 0u};
    uint32_t ids[3];
    for (int k = 0; k < 3; ++k) {
      ids[k] = fresh();
      declarations.insert(declarations.end(), {word(4, 43 /*Constant*/), u32, ids[k], scalar[k]});
    }
    if (n == 1) {
      w = {u32, boolean, ids[0], ids[1], ids[2]};
      return w;
    }
    for (auto [table, component] : {std::pair{vec_u, u32}, std::pair{vec_b, boolean}})
      if (!table[n]) {
        table[n] = fresh();
        declarations.insert(declarations.end(), {word(4, 23 /*TypeVector*/), table[n], component, n});
      }
    w.uint_type = vec_u[n];
    w.bool_type = vec_b[n];
    uint32_t* out[3] = {&w.exponent, &w.sign, &w.zero};
    for (int k = 0; k < 3; ++k) {
      *out[k] = fresh();
      declarations.insert(declarations.end(), {word(3 + n, 44 /*ConstantComposite*/), vec_u[n], *out[k]});
      for (uint32_t c = 0; c < n; ++c) declarations.push_back(ids[k]);
    }
    return w;
  }
};

/// Where a module's sections end and what the rules need from them.
struct Sections {
  std::vector<uint32_t> entries, arithmetic; // the entry points; the float arithmetic's results
  std::unordered_set<uint32_t> decorated;    // the ids already NoContraction
  size_t after_caps = 5, after_modes = 5, preamble_end = 5, functions = 0;
};

/// One pass over the module's words: its sections and its float, uint and bool types. False when the
/// words are not a module this can fix.
bool scanSections(std::span<const uint32_t> code, Sections& s, FlushTypes& types) {
  s.functions = code.size();
  bool in_preamble = true;
  for (size_t w = 5; w < code.size();) {
    const uint32_t count = code[w] >> 16, op = code[w] & 0xFFFFu;
    if (count == 0 || w + count > code.size()) return false;
    if (op == kOpCapability) s.after_caps = w + count;
    if (op == kOpEntryPoint && count >= 3) s.entries.push_back(code[w + 2]);
    if (op == kOpEntryPoint || op == kOpExecutionMode || op == kOpExecutionModeId) s.after_modes = w + count;
    if (op == kOpDecorate && count >= 3 && code[w + 2] == kDecorationNoContraction) s.decorated.insert(code[w + 1]);
    if (in_preamble && isPreamble(op))
      s.preamble_end = w + count;
    else
      in_preamble = false;
    if (op == 54 /*Function*/ && s.functions == code.size()) s.functions = w;
    if (op == 22 /*TypeFloat*/ && count == 3 && code[w + 2] == 32) types.f32 = code[w + 1];
    if (op == 21 /*TypeInt*/ && count == 4 && code[w + 2] == 32 && code[w + 3] == 0) types.u32 = code[w + 1];
    if (op == 20 /*TypeBool*/ && count == 2) types.boolean = code[w + 1];
    if (op == 23 /*TypeVector*/ && count == 4 && code[w + 3] >= 2 && code[w + 3] <= 4) {
      const uint32_t component = code[w + 2], n = code[w + 3];
      if (component == types.f32) types.vec_f[n] = code[w + 1];
      if (component == types.u32) types.vec_u[n] = code[w + 1];
      if (component == types.boolean) types.vec_b[n] = code[w + 1];
    }
    if (isFloatArithmetic(op) && count >= 3) s.arithmetic.push_back(code[w + 2]);
    w += count;
  }
  return true;
}

/// The storage class of each pointer type and pointer (variables and access chains).
std::unordered_map<uint32_t, uint32_t> pointerClasses(std::span<const uint32_t> code) {
  std::unordered_map<uint32_t, uint32_t> pointer_class;
  for (size_t w = 5; w < code.size();) {
    const uint32_t count = code[w] >> 16, op = code[w] & 0xFFFFu;
    if (op == 32 /*TypePointer*/ && count == 4) pointer_class[code[w + 1]] = code[w + 2];
    // Variable, AccessChain, InBoundsAccessChain, PtrAccessChain: the class of their pointer type
    if ((op == 59 || op == 65 || op == 66 || op == 67) && count >= 3)
      if (auto it = pointer_class.find(code[w + 1]); it != pointer_class.end()) pointer_class[code[w + 2]] = it->second;
    w += count;
  }
  return pointer_class;
}

/// Appends %result = the zero of %in's sign where %in's exponent is 0 (a denormal), else %in.
void appendFlush(std::vector<uint32_t>& out, FlushTypes& types, uint32_t type, uint32_t result, uint32_t in,
                 uint32_t width) {
  const FlushTypes::Width& t = types.width(width);
  const uint32_t bits = types.fresh(), exponent = types.fresh(), tiny = types.fresh(), sign = types.fresh(),
                 zero = types.fresh();
  // clang-format off
  out.insert(out.end(), {word(4, 124 /*Bitcast*/),    t.uint_type, bits,     in,
                         word(5, 199 /*BitwiseAnd*/), t.uint_type, exponent, bits,     t.exponent,
                         word(5, 170 /*IEqual*/),     t.bool_type, tiny,     exponent, t.zero,
                         word(5, 199 /*BitwiseAnd*/), t.uint_type, sign,     bits,     t.sign,
                         word(4, 124 /*Bitcast*/),    type,        zero,     sign,
                         word(6, 169 /*Select*/),     type,        result,   tiny,     zero, in});
  // clang-format on
}

} // namespace

std::vector<uint32_t> applyFloatRules(std::span<const uint32_t> code, const FloatRules& rules) {
  if (code.size() < 5) return {code.begin(), code.end()};
  const bool flush_in_shader = rules.denormals == Denormals::FlushInShader;
  Sections sec;
  FlushTypes types;
  types.bound = code[3];
  if (!scanSections(code, sec, types)) return {code.begin(), code.end()}; // not ours to fix
  // A float loaded from the host's memory (a buffer, a uniform, a push constant, a buffer reached by
  // device address) or made from bits is flushed too: a denormal the host wrote reads as zero, as
  // the CPU's DAZ reads it.
  const std::unordered_map<uint32_t, uint32_t> pointer_class =
      flush_in_shader ? pointerClasses(code) : std::unordered_map<uint32_t, uint32_t>{};
  auto fromHost = [&](uint32_t pointer) {
    auto it = pointer_class.find(pointer);
    return it != pointer_class.end() &&
           (it->second == 2 || it->second == 9 || it->second == 12 || it->second == 5349 /*PhysicalStorageBuffer*/);
  };
  // The component count of the float result of the instruction at w when it is flushed, else 0
  auto flushedWidth = [&](size_t w) -> uint32_t {
    const uint32_t count = code[w] >> 16, op = code[w] & 0xFFFFu;
    const bool flushed =
        flush_in_shader && w >= sec.functions && count >= 3 &&
        (canMakeDenormal(op) || op == 124 /*Bitcast*/ || (op == 61 /*Load*/ && count >= 4 && fromHost(code[w + 3])));
    return flushed ? types.floatWidth(code[w + 1]) : 0;
  };
  // Each flushed result %r is computed into a new id %raw, and %r becomes the flushed value: every
  // use of %r (and each decoration of the instruction) follows unchanged.
  std::unordered_map<uint32_t, uint32_t> raw; // %r -> %raw
  for (size_t w = sec.functions; w < code.size(); w += code[w] >> 16)
    if (const uint32_t n = flushedWidth(w)) {
      raw[code[w + 2]] = types.fresh();
      types.width(n); // declares the types and constants of its flush
    }
  auto renamed = [&](uint32_t id) {
    auto it = raw.find(id);
    return it == raw.end() ? id : it->second;
  };
  std::vector<uint32_t> caps, modes, decorations;
  auto mode = [&](uint32_t cap, uint32_t m) {
    caps.insert(caps.end(), {word(2, kOpCapability), cap});
    for (uint32_t e : sec.entries) modes.insert(modes.end(), {word(4, kOpExecutionMode), e, m, 32u});
  };
  if (rules.rounding_rte) mode(kCapRoundingModeRTE, kModeRoundingModeRTE);
  if (rules.denormals == Denormals::FlushToZero) mode(kCapDenormFlushToZero, kModeDenormFlushToZero);
  for (uint32_t id : sec.arithmetic)
    if (sec.decorated.insert(id).second)
      decorations.insert(decorations.end(), {word(3, kOpDecorate), renamed(id), kDecorationNoContraction});
  // Splice the runs in at their sections (capabilities < modes < decorations < types < functions)
  std::vector<uint32_t> out;
  out.reserve(code.size() + caps.size() + modes.size() + decorations.size() + types.declarations.size() +
              raw.size() * 30);
  out.insert(out.end(), code.begin(), code.begin() + 5);
  for (size_t w = 5; w < code.size();) {
    const uint32_t count = code[w] >> 16, op = code[w] & 0xFFFFu;
    if (w == sec.after_caps) out.insert(out.end(), caps.begin(), caps.end());
    if (w == sec.after_modes) out.insert(out.end(), modes.begin(), modes.end());
    if (w == sec.preamble_end) out.insert(out.end(), decorations.begin(), decorations.end());
    if (w == sec.functions) out.insert(out.end(), types.declarations.begin(), types.declarations.end());
    const size_t at = out.size();
    out.insert(out.end(), code.begin() + long(w), code.begin() + long(w + count));
    if ((op == kOpDecorate || op == 332 /*DecorateId*/ || op == 5632 /*DecorateString*/) && count >= 2)
      out[at + 1] = renamed(out[at + 1]);
    if (const uint32_t n = flushedWidth(w)) {
      out[at + 2] = raw[code[w + 2]];
      appendFlush(out, types, code[w + 1], code[w + 2], out[at + 2], n);
    }
    w += count;
  }
  if (sec.functions == code.size()) out.insert(out.end(), types.declarations.begin(), types.declarations.end());
  if (sec.preamble_end == code.size()) out.insert(out.end(), decorations.begin(), decorations.end());
  out[3] = types.bound; // the ids the flushes took
  return out;
}

std::vector<std::string> inexactOperations(std::span<const uint32_t> code) {
  constexpr uint32_t kOpName = 5, kOpExtInstImport = 11, kOpExtInst = 12, kOpFunction = 54, kOpFunctionCall = 57;
  constexpr uint32_t kOpFDiv = 136, kOpFRem = 140, kOpFMod = 141, kSqrt = 31;
  std::unordered_map<uint32_t, std::string> names;
  std::unordered_set<uint32_t> glsl;
  for (size_t w = 5; w < code.size();) {
    const uint32_t count = code[w] >> 16, op = code[w] & 0xFFFFu;
    if (count == 0 || w + count > code.size()) break;
    if ((op == kOpName && count >= 3) || (op == kOpExtInstImport && count >= 3)) {
      const char* text = reinterpret_cast<const char*>(&code[w + 2]);
      const std::string str(text, strnlen(text, (count - 2) * 4));
      if (op == kOpName) names[code[w + 1]] = str;
      if (op == kOpExtInstImport && str == "GLSL.std.450") glsl.insert(code[w + 1]);
    }
    w += count;
  }
  auto named = [&](uint32_t id, std::string_view prefix) {
    auto it = names.find(id);
    return it != names.end() && std::string_view(it->second).substr(0, prefix.size()) == prefix;
  };
  auto nameOf = [&](uint32_t id) {
    auto it = names.find(id);
    if (it != names.end()) return it->second.substr(0, it->second.find('('));
    // (appended to "%", not "%" + ...: GCC 12 at -O3 takes operator+(const char*, std::string&&)
    // for an overlapping copy, a false -Wrestrict that -Werror refuses)
    std::string n = "%";
    return n.append(std::to_string(id));
  };
  std::vector<std::string> found;
  uint32_t function = 0;
  for (size_t w = 5; w < code.size();) {
    const uint32_t count = code[w] >> 16, op = code[w] & 0xFFFFu;
    if (count == 0 || w + count > code.size()) break;
    if (op == kOpFunction && count >= 3) function = code[w + 2];
    std::string what;
    if (op == kOpFDiv && !named(function, "deviceDiv(")) what = "OpFDiv";
    if (op == kOpFRem || op == kOpFMod) what = op == kOpFRem ? "OpFRem" : "OpFMod";
    if (op == kOpExtInst && count >= 5 && glsl.count(code[w + 3]) && code[w + 4] == kSqrt &&
        !named(function, "deviceSqrt("))
      what = "GLSL.std.450 Sqrt";
    if (op == kOpFunctionCall && count >= 4) {
      if (named(code[w + 3], "deviceDiv(") && !named(function, "exactDiv(")) what = "a call of deviceDiv";
      if (named(code[w + 3], "deviceSqrt(") && !named(function, "exactSqrt(")) what = "a call of deviceSqrt";
    }
    if (!what.empty()) found.push_back("in " + nameOf(function) + ": " + what);
    w += count;
  }
  return found;
}

} // namespace tender::gpu
