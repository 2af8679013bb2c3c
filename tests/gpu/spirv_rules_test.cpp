// The float rules written into every simulation shader: NoContraction on every float operation,
// none of the built-ins whose order or precision a device chooses, and modules that the SPIR-V
// validator accepts under each combination of float controls.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
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

TEST(SpirvRules, TheValidatorAcceptsEveryRewrittenShader) {
  const std::string spirv_val = spirvVal();
  if (spirv_val.empty()) GTEST_SKIP() << "spirv-val not found at configure time";
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "tender_spirv_rules";
  std::filesystem::create_directories(dir);
  for (std::string_view key : simShaderKeys()) {
    for (const FloatRules& rules : kAllRules) {
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
