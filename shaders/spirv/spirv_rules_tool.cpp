// Build step of the simulation's shaders (shaders/CMakeLists.txt):
//   tender-spirv-rules IN.spv OUT.spv     NoContraction on every float operation (before spirv-opt,
//                                         which would otherwise fuse a * b + c into Fma); refuses a
//                                         shader that divides or takes a square root outside
//                                         exact_math.h's correction (inexactOperations)
//   tender-spirv-rules --embed IN.spv OUT the words deflated (zlib), as the initialiser of a C array
//                                         of words: the SPIR-V's word count, the deflated bytes'
//                                         count, then those bytes four to a word (little-endian);
//                                         the embedded shaders' registry inflates them
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <zlib.h>

#include "spirv_rules.h"

int main(int argc, char** argv) {
  const bool embed = argc == 4 && std::strcmp(argv[1], "--embed") == 0;
  if (argc != 3 && !embed) {
    std::fprintf(stderr, "usage: tender-spirv-rules [--embed] IN.spv OUT\n");
    return 2;
  }
  const char* in_path = argv[argc - 2];
  const char* out_path = argv[argc - 1];
  std::ifstream in(in_path, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) {
    std::fprintf(stderr, "tender-spirv-rules: error: cannot read %s\n", in_path);
    return 2;
  }
  if (bytes.size() < 20 || bytes.size() % 4 != 0) {
    std::fprintf(stderr, "tender-spirv-rules: error: %s is not SPIR-V\n", in_path);
    return 2;
  }
  std::vector<uint32_t> words(bytes.size() / 4);
  std::memcpy(words.data(), bytes.data(), bytes.size());
  // Written whole to a temporary name, then renamed: a failed step leaves no half-written output
  const std::string tmp_path = std::string(out_path) + ".tmp";
  std::ofstream out(tmp_path, std::ios::binary | std::ios::trunc);
  if (embed) {
    uLongf packed_size = compressBound(uLong(bytes.size()));
    std::vector<uint32_t> packed(2 + (packed_size + 3) / 4, 0u);
    if (compress2(reinterpret_cast<Bytef*>(packed.data() + 2), &packed_size,
                  reinterpret_cast<const Bytef*>(bytes.data()), uLong(bytes.size()), Z_BEST_COMPRESSION) != Z_OK) {
      std::fprintf(stderr, "tender-spirv-rules: error: cannot deflate %s\n", in_path);
      return 2;
    }
    packed[0] = uint32_t(words.size());
    packed[1] = uint32_t(packed_size);
    packed.resize(2 + (packed_size + 3) / 4);
    for (size_t i = 0; i < packed.size(); ++i) out << packed[i] << (i % 8 == 7 ? ",\n" : ",");
    out << "\n";
  } else {
    if (const std::vector<std::string> found = tender::gpu::inexactOperations(words); !found.empty()) {
      for (const std::string& f : found)
        std::fprintf(stderr, "tender-spirv-rules: error: %s: %s (exact_math.h: simDiv, simSqrt)\n", in_path, f.c_str());
      out.close();
      std::remove(tmp_path.c_str());
      return 2;
    }
    const std::vector<uint32_t> ruled = tender::gpu::applyFloatRules(words, {false, tender::gpu::Denormals::AsWritten});
    out.write(reinterpret_cast<const char*>(ruled.data()), std::streamsize(ruled.size() * 4));
  }
  out.close();
  if (!out.good() || std::rename(tmp_path.c_str(), out_path) != 0) {
    std::remove(tmp_path.c_str());
    std::fprintf(stderr, "tender-spirv-rules: error: cannot write %s\n", out_path);
    return 2;
  }
  return 0;
}
