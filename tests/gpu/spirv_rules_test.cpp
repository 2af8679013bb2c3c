// The float rules written into every simulation shader: NoContraction on every float operation,
// none of the built-ins whose order or precision a device chooses, and modules that the SPIR-V
// validator accepts under each combination of float controls.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "gpu/shaders.h"
#include "spirv_rules.h"

using namespace tender::gpu;

namespace {

struct Instruction {
  uint32_t op;
  std::span<const uint32_t> words; // the whole instruction
};

std::vector<Instruction> instructions(std::span<const uint32_t> code) {
  std::vector<Instruction> out;
  for (size_t w = 5; w < code.size();) {
    const uint32_t count = code[w] >> 16;
    if (count == 0 || w + count > code.size()) break;
    out.push_back({code[w] & 0xFFFFu, code.subspan(w, count)});
    w += count;
  }
  return out;
}

// GLSL.std.450 instructions that are exact on every device: abs, floor, roundEven (the contact's
// fixed point; not Round, whose halves the device chooses), min/max/clamp, bit scans, sign, and Sqrt
// (only ever the approximation that exact_math.h corrects).
const std::set<uint32_t> kExactExtInsts = {2 /*RoundEven*/,
                                           3 /*Trunc*/,
                                           4 /*FAbs*/,
                                           5 /*SAbs*/,
                                           6 /*FSign*/,
                                           7 /*SSign*/,
                                           8 /*Floor*/,
                                           9 /*Ceil*/,
                                           31 /*Sqrt*/,
                                           37,
                                           38,
                                           39,
                                           40,
                                           41,
                                           42,
                                           43,
                                           44,
                                           45,
                                           /*min, max, clamp*/ 73,
                                           74,
                                           75 /*FindILsb, FindSMsb, FindUMsb*/};

const FloatRules kAllRules[] = {{false, Denormals::FlushInShader},
                                {true, Denormals::FlushInShader},
                                {true, Denormals::FlushToZero},
                                {false, Denormals::FlushToZero},
                                {false, Denormals::AsWritten}};

// The rules spirv-val checks here: those lavapipe does not run. Lavapipe's own ({true,
// FlushInShader}: it rounds to nearest even and cannot be asked to flush) are checked in every GPU
// test, whose validation layer runs spirv-val on each module it is given; {true, FlushToZero}
// stands for {false, FlushToZero} too, which is it less one capability and execution mode.
const FloatRules kValidatedRules[] = {
    {false, Denormals::FlushInShader}, {true, Denormals::FlushToZero}, {false, Denormals::AsWritten}};

} // namespace

TEST(SpirvRules, EveryFloatOperationOfEverySimShaderIsNoContraction) {
  ASSERT_GT(simShaderKeys().size(), 15u);
  for (std::string_view key : simShaderKeys()) {
    for (const FloatRules& rules : kAllRules) {
      const std::vector<uint32_t> code = applyFloatRules(simShader(key), rules);
      std::unordered_set<uint32_t> no_contraction, arithmetic;
      uint32_t modes = 0;
      for (const Instruction& in : instructions(code)) {
        if (in.op == 71 && in.words.size() >= 3 && in.words[2] == 42) no_contraction.insert(in.words[1]);
        if (isFloatArithmetic(in.op)) arithmetic.insert(in.words[2]);
        if (in.op == 16 && in.words.size() == 4 && in.words[3] == 32) ++modes;
      }
      if (key == "project.comp" || key == "tick_fused.comp") {
        EXPECT_GT(arithmetic.size(), 10u) << key;
      }
      for (uint32_t id : arithmetic) EXPECT_TRUE(no_contraction.count(id)) << key << ": %" << id << " may be fused";
      EXPECT_EQ(modes, uint32_t(rules.rounding_rte) + uint32_t(rules.denormals == Denormals::FlushToZero)) << key;
    }
  }
}

TEST(SpirvRules, EveryFloatTheHostWroteIsFlushedWhereTheShaderFlushes) {
  // A float loaded from memory the host writes (a uniform, a push constant, a storage buffer, or a
  // fleet's buffers reached by device address) goes through the flush (a bitcast first) before
  // any use, as the CPU's DAZ reads a denormal as zero
  const std::set<uint32_t> host = {2 /*Uniform*/, 9 /*PushConstant*/, 12 /*StorageBuffer*/,
                                   5349 /*PhysicalStorageBuffer*/};
  uint32_t batch_loads = 0;
  for (std::string_view key : simShaderKeys()) {
    const std::vector<uint32_t> code = applyFloatRules(simShader(key), {false, Denormals::FlushInShader});
    std::unordered_set<uint32_t> floats, host_pointers;
    std::unordered_map<uint32_t, uint32_t> pointer_class;
    std::vector<uint32_t> loads;
    std::unordered_set<uint32_t> bitcast_operands;
    for (const Instruction& in : instructions(code)) {
      if (in.op == 22 /*TypeFloat*/ && in.words[2] == 32) floats.insert(in.words[1]);
      if (in.op == 23 /*TypeVector*/ && floats.count(in.words[2])) floats.insert(in.words[1]);
      if (in.op == 32 /*TypePointer*/) pointer_class[in.words[1]] = in.words[2];
      if ((in.op == 59 || in.op == 65 || in.op == 66 || in.op == 67) && pointer_class.count(in.words[1]) &&
          host.count(pointer_class[in.words[1]]))
        host_pointers.insert(in.words[2]);
      if (in.op == 61 /*Load*/ && floats.count(in.words[1]) && host_pointers.count(in.words[3]))
        loads.push_back(in.words[2]);
      if (in.op == 124 /*Bitcast*/) bitcast_operands.insert(in.words[3]);
    }
    if (key.find(".batch") != std::string_view::npos || key == "tick_batch.comp") batch_loads += uint32_t(loads.size());
    for (uint32_t id : loads) EXPECT_TRUE(bitcast_operands.count(id)) << key << ": %" << id << " is used unflushed";
  }
  EXPECT_GT(batch_loads, 100u); // the fleet's shaders load their floats by device address
}

TEST(SpirvRules, NoSimShaderUsesABuiltInWhoseResultTheDeviceChooses) {
  for (std::string_view key : simShaderKeys()) {
    for (const Instruction& in : instructions(simShader(key))) {
      EXPECT_NE(in.op, 148u) << key << " uses OpDot (dot(): the order of its sum is the device's)";
      if (in.op == 12 /*OpExtInst*/) {
        EXPECT_TRUE(kExactExtInsts.count(in.words[4])) << key << " uses GLSL.std.450 instruction " << in.words[4];
      }
    }
  }
}

// spirv-val: $TENDER_SPIRV_VAL when set (the copy bundled beside the tests by tools/gpu-bundle),
// otherwise the one found at configure time.
namespace {
std::string spirvVal() {
  if (const char* path = std::getenv("TENDER_SPIRV_VAL"); path && *path) return path;
#ifdef TENDER_SPIRV_VAL
  return TENDER_SPIRV_VAL;
#else
  return "";
#endif
}
} // namespace

// A fleet's kernels reach a sheet's buffers by device address (PhysicalStorageBuffer). Mesa's
// lavapipe (22.3) reads a component of a vector, loaded apart from the whole vector at the same
// address, as the vector's first: `vec4 a = v[i].start; float b = v[i].start.w;` gave b = a.x (a
// batched contact step that never cut a step). So no kernel loads both a vector and one of its
// components other than the first through the same chain: it loads the vector once and takes the
// component from it.
TEST(SpirvRules, NoSimShaderLoadsAVectorAndOneOfItsComponentsByDeviceAddress) {
  uint32_t chains = 0;
  for (std::string_view key : simShaderKeys()) {
    std::unordered_map<uint32_t, uint32_t> pointer_class;
    std::unordered_map<uint32_t, std::vector<uint32_t>> chain; // access chain -> base and indices
    std::set<std::vector<uint32_t>> loaded;                    // the chains loaded
    std::unordered_map<uint32_t, uint32_t> constant;
    for (const Instruction& in : instructions(simShader(key))) {
      if (in.op == 43 /*Constant*/ && in.words.size() == 4) constant[in.words[2]] = in.words[3];
      if (in.op == 32 /*TypePointer*/) pointer_class[in.words[1]] = in.words[2];
      if ((in.op == 65 || in.op == 66) && pointer_class[in.words[1]] == 5349 /*PhysicalStorageBuffer*/)
        chain[in.words[2]].assign(in.words.begin() + 3, in.words.end());
      if (in.op == 61 /*Load*/ && chain.count(in.words[3])) loaded.insert(chain[in.words[3]]);
    }
    chains += uint32_t(loaded.size());
    for (const std::vector<uint32_t>& c : loaded) {
      // The chain one index shorter, loaded too: the vector whose component c is
      if (c.size() < 3 || constant[c.back()] == 0) continue;
      const std::vector<uint32_t> whole(c.begin(), c.end() - 1);
      EXPECT_FALSE(loaded.count(whole)) << key << ": loads a vector (base %" << c[0] << ", " << c.size() - 2
                                        << " indices) and its component " << constant[c.back()] << " apart";
    }
  }
  EXPECT_GT(chains, 100u); // the fleet's kernels load through buffer references
}

// Lavapipe's load vectoriser (Mesa 22.3) merges components of one vector loaded apart by device
// address into one load that it can read wrongly: the fleet's fused contact kernel, reading
// `u.contact_grid.y` and `.z` apart (now ContactGrid's counts and fills), cleared the wrong buckets of its grid (counts
// of billions, then a scatter far out of bounds). So a kernel loads a vector it reaches by device address whole, at
// most once per chain, or one component of it alone: never two components apart; and so for the fields of the uniforms'
// topics (SimUniforms' 16-byte structs). Loads through a pointer held in a variable (a fleet's `u`, loaded again at
// each use) count as one chain.
namespace {

// The components of each vector a shader loads through a chain from a device address (a
// pointer to PhysicalStorageBuffer), by the vector's chain, with its path for the messages.
struct VectorLoads {
  std::map<std::vector<uint32_t>, std::set<uint32_t>> components;
  std::map<std::vector<uint32_t>, std::string> paths;
};

VectorLoads deviceAddressVectorLoads(const std::vector<Instruction>& code) {
  VectorLoads loads;
  std::unordered_map<uint32_t, const Instruction*> type;    // type id -> its declaration
  std::unordered_map<uint32_t, uint32_t> type_of, constant; // value id -> type id, constant value
  std::unordered_map<uint32_t, uint32_t> loaded_from;       // value id -> the variable it was loaded from
  std::unordered_map<uint32_t, uint32_t> root_type;         // a chain's root -> its pointer type
  std::unordered_map<uint32_t, std::string> name;           // OpName, for the messages
  std::map<std::pair<uint32_t, uint32_t>, std::string> member_name;
  std::unordered_map<uint32_t, std::vector<uint32_t>> chain; // access chain -> root and indices
  std::unordered_set<uint32_t> variables;
  for (const Instruction& in : code) {
    if (in.op >= 19 && in.op <= 39 && in.words.size() >= 2) type[in.words[1]] = &in; // OpType*
    if (in.op == 59 /*Variable*/) variables.insert(in.words[2]);
    if (in.op == 43 /*Constant*/ && in.words.size() == 4) constant[in.words[2]] = in.words[3];
    if (in.op == 5 /*Name*/) name[in.words[1]] = reinterpret_cast<const char*>(&in.words[2]);
    if (in.op == 6 /*MemberName*/)
      member_name[{in.words[1], in.words[2]}] = reinterpret_cast<const char*>(&in.words[3]);
  }
  // The type that index `index` of a value of type `t` has
  auto member = [&](uint32_t t, uint32_t index) -> uint32_t {
    const Instruction* d = type.count(t) ? type[t] : nullptr;
    if (!d) return 0;
    if (d->op == 30 /*Struct*/) return constant.count(index) ? d->words[2 + constant[index]] : 0;
    if (d->op == 23 || d->op == 24 || d->op == 28 || d->op == 29) return d->words[2]; // vector, matrix, arrays
    return 0;
  };
  for (const Instruction& in : code) {
    if (in.op == 55 /*FunctionParameter*/ || in.op == 120 /*ConvertUToPtr*/ || in.op == 124 /*Bitcast*/)
      type_of[in.words[2]] = in.words[1];
    if (in.op == 61 /*Load*/) {
      type_of[in.words[2]] = in.words[1];
      if (variables.count(in.words[3])) loaded_from[in.words[2]] = in.words[3];
    }
    if (in.op != 65 && in.op != 66) continue; // (InBounds)AccessChain
    const uint32_t ptr_type = in.words[1], base = in.words[3];
    if (!type.count(ptr_type) || type[ptr_type]->words[2] != 5349 /*PhysicalStorageBuffer*/) continue;
    std::vector<uint32_t> c;
    if (chain.count(base)) { // a chain from a chain
      c = chain[base];
    } else if (loaded_from.count(base)) { // the pointer a variable holds, as its root
      c = {loaded_from[base]};
      root_type[loaded_from[base]] = type_of[base];
    } else {
      c = {base};
      root_type[base] = type_of[base];
    }
    c.insert(c.end(), in.words.begin() + 4, in.words.end());
    chain[in.words[2]] = c;
  }
  // Every load through a chain whose last step takes a constant component of a vector
  for (const Instruction& in : code) {
    if (in.op != 61 || !chain.count(in.words[3])) continue;
    const std::vector<uint32_t>& c = chain[in.words[3]];
    if (c.size() < 2) continue;
    // The root's pointee type, then every index but the last
    const uint32_t root = root_type[c[0]];
    uint32_t t = type.count(root) && type[root]->op == 32 ? type[root]->words[3] : 0;
    std::string path = "%"; // (appended to, not "%" + ...: see nameOf in spirv_rules.cpp)
    path = name.count(c[0]) ? name[c[0]] : name.count(t) ? name[t] : path + std::to_string(c[0]);
    uint32_t parent = 0;
    for (size_t k = 1; k + 1 < c.size() && t; ++k) {
      if (type.count(t) && type[t]->op == 30 && constant.count(c[k]))
        path += "." + member_name[{t, constant[c[k]]}];
      else
        path += "[]";
      parent = t;
      t = member(t, c[k]);
    }
    // A vector, or a topic of the uniforms (SimUniforms' 16-byte structs), whose fields it merges alike
    const bool topic = t && type.count(t) && type[t]->op == 30 && name.count(parent) && name[parent] == "SimUniforms";
    if (!t || !type.count(t) || (type[t]->op != 23 /*Vector*/ && !topic) || !constant.count(c.back())) continue;
    const std::vector<uint32_t> vector(c.begin(), c.end() - 1);
    loads.components[vector].insert(constant[c.back()]);
    loads.paths[vector] = path;
  }
  return loads;
}

} // namespace

TEST(SpirvRules, NoSimShaderLoadsTwoComponentsOfAVectorApartByDeviceAddress) {
  // (nor two fields of one of the uniforms' topics)
  uint32_t vectors = 0;
  for (std::string_view key : simShaderKeys()) {
    const VectorLoads loads = deviceAddressVectorLoads(instructions(simShader(key)));
    for (const auto& [vector, loaded] : loads.components) {
      ++vectors;
      EXPECT_LT(loaded.size(), 2u) << key << ": loads " << loaded.size() << " components of " << loads.paths.at(vector)
                                   << " apart";
    }
  }
  EXPECT_GT(vectors, 0u); // some component alone is loaded by device address
}

TEST(SpirvRules, TheValidatorAcceptsEveryRewrittenShader) {
  const std::string spirv_val = spirvVal();
  if (spirv_val.empty()) GTEST_SKIP() << "spirv-val not found at configure time";
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "tender_spirv_rules";
  std::filesystem::create_directories(dir);
  for (std::string_view key : simShaderKeys()) {
    for (const FloatRules& rules : kValidatedRules) {
      const std::vector<uint32_t> code = applyFloatRules(simShader(key), rules);
      const std::filesystem::path file = dir / (std::string(key) + ".spv");
      std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(code.data()), long(code.size() * 4));
      const std::string cmd = spirv_val + " --target-env vulkan1.3 " + file.string() + " 2>&1";
      EXPECT_EQ(std::system(cmd.c_str()), 0)
          << key << " with rte " << rules.rounding_rte << ", denormals " << denormalsName(rules.denormals);
    }
  }
  std::filesystem::remove_all(dir);
}
