// The glTF export read back with tinygltf: counts, index ranges, accessor bounds, the material,
// the embedded texture (decoded), and the morph-target animation of several frames.
#include <cmath>
#include <cstring>

#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include "core/sheet.h"
#include "export/gltf.h"

namespace tender {
namespace {

// A 16 x 24 sheet's start state, with normals +z.
SimState sheetState(const SheetTopology& topo) {
  SimState s;
  s.pos = topo.rest_pos;
  for (auto& p : s.pos) p.w = 1.0f;
  s.normal.assign(s.pos.size(), glm::vec4(0.0f, 0.0f, 1.0f, 0.0f));
  s.triangles = topo.triangles;
  s.triangle_count = topo.triangleCount();
  return s;
}

SheetTopology smallSheet() {
  SimParams p;
  p.cols = 16;
  p.rows = 24;
  return buildSheet(p);
}

tinygltf::Model load(const std::string& bytes, bool binary) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model m;
  std::string err, warn;
  bool ok = binary ? loader.LoadBinaryFromMemory(&m, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                                 unsigned(bytes.size()))
                   : loader.LoadASCIIFromString(&m, &err, &warn, bytes.data(), unsigned(bytes.size()), "");
  EXPECT_TRUE(ok) << err;
  EXPECT_TRUE(err.empty()) << err;
  return m;
}

// The floats of a float accessor (tightly packed).
std::vector<float> floats(const tinygltf::Model& m, int accessor) {
  const auto& a = m.accessors[size_t(accessor)];
  const auto& v = m.bufferViews[size_t(a.bufferView)];
  const auto& b = m.buffers[size_t(v.buffer)];
  EXPECT_EQ(a.componentType, TINYGLTF_COMPONENT_TYPE_FLOAT);
  const size_t n = a.count * size_t(tinygltf::GetNumComponentsInType(uint32_t(a.type)));
  EXPECT_LE(v.byteOffset + a.byteOffset + n * 4, b.data.size());
  std::vector<float> out(n);
  std::memcpy(out.data(), b.data.data() + v.byteOffset + a.byteOffset, n * 4);
  return out;
}

std::vector<uint32_t> indices(const tinygltf::Model& m, int accessor) {
  const auto& a = m.accessors[size_t(accessor)];
  const auto& v = m.bufferViews[size_t(a.bufferView)];
  EXPECT_EQ(a.componentType, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT);
  std::vector<uint32_t> out(a.count);
  std::memcpy(out.data(), m.buffers[size_t(v.buffer)].data.data() + v.byteOffset + a.byteOffset, a.count * 4);
  return out;
}

// min and max of every VEC3 accessor match its data.
void expectBounds(const tinygltf::Model& m, int accessor) {
  const auto& a = m.accessors[size_t(accessor)];
  ASSERT_EQ(a.minValues.size(), 3u);
  ASSERT_EQ(a.maxValues.size(), 3u);
  auto f = floats(m, accessor);
  for (int k = 0; k < 3; ++k) {
    float lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < a.count; ++i)
      lo = std::min(lo, f[i * 3 + size_t(k)]), hi = std::max(hi, f[i * 3 + size_t(k)]);
    EXPECT_EQ(float(a.minValues[size_t(k)]), lo);
    EXPECT_EQ(float(a.maxValues[size_t(k)]), hi);
  }
}

TEST(Gltf, FormatByExtension) {
  EXPECT_EQ(meshFormatFor("a/b.glb"), MeshFormat::Glb);
  EXPECT_EQ(meshFormatFor("B.GLTF"), MeshFormat::Gltf);
  EXPECT_EQ(meshFormatFor("x.ply"), MeshFormat::Ply);
  EXPECT_EQ(meshFormatFor("/dev/stdout"), MeshFormat::Ply);
  EXPECT_EQ(meshFormatFor("dir.d/noext"), MeshFormat::Ply);
  EXPECT_EQ(meshFormatFor("x.obj"), std::nullopt);
  EXPECT_EQ(meshFormatFor("x.glb.txt"), std::nullopt);
}

TEST(Gltf, StaticSheetReadsBack) {
  const SheetTopology topo = smallSheet();
  SimState s = sheetState(topo);
  s.triangle_count -= 10; // ten torn
  MeshScene scene;
  scene.uv = topo.uv;
  scene.texture_png = receiptPng("tender");
  ASSERT_EQ(scene.texture_png.empty(), !haveReceiptTexture());
  for (bool binary : {true, false}) {
    std::string error;
    auto bytes = encodeGltf(scene, {meshFrame(s, 0.0)}, binary, error);
    ASSERT_TRUE(bytes) << error;
    if (binary) {
      EXPECT_EQ(bytes->substr(0, 4), "glTF");
    }
    tinygltf::Model m = load(*bytes, binary);
    ASSERT_EQ(m.meshes.size(), 1u);
    ASSERT_EQ(m.nodes.size(), 1u);
    EXPECT_EQ(m.nodes[0].mesh, 0);
    EXPECT_TRUE(m.animations.empty());
    const auto& prim = m.meshes[0].primitives.at(0);
    EXPECT_EQ(prim.mode, TINYGLTF_MODE_TRIANGLES);
    EXPECT_TRUE(prim.targets.empty());
    const size_t n = topo.particleCount();
    for (const char* attr : {"POSITION", "NORMAL", "TEXCOORD_0"}) {
      ASSERT_TRUE(prim.attributes.count(attr)) << attr;
      EXPECT_EQ(m.accessors[size_t(prim.attributes.at(attr))].count, n) << attr;
    }
    expectBounds(m, prim.attributes.at("POSITION"));
    auto pos = floats(m, prim.attributes.at("POSITION"));
    for (size_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) EXPECT_EQ(pos[i * 3 + size_t(k)], s.pos[i][k]);
    auto uv = floats(m, prim.attributes.at("TEXCOORD_0"));
    EXPECT_EQ(uv[2 * (n - 1)], topo.uv[n - 1].x);
    EXPECT_EQ(uv[2 * (n - 1) + 1], topo.uv[n - 1].y);
    auto idx = indices(m, prim.indices);
    ASSERT_EQ(idx.size(), size_t(s.triangle_count) * 3);
    for (size_t k = 0; k < idx.size(); ++k) {
      ASSERT_LT(idx[k], n);
      EXPECT_EQ(idx[k], s.triangles[k / 3][int(k % 3)]);
    }
    const auto& ia = m.accessors[size_t(prim.indices)];
    EXPECT_EQ(ia.minValues.at(0), double(*std::min_element(idx.begin(), idx.end())));
    EXPECT_EQ(ia.maxValues.at(0), double(*std::max_element(idx.begin(), idx.end())));

    ASSERT_EQ(m.materials.size(), 1u);
    const auto& mat = m.materials[0];
    EXPECT_TRUE(mat.doubleSided);
    EXPECT_EQ(mat.pbrMetallicRoughness.metallicFactor, 0.0);
    EXPECT_FLOAT_EQ(float(mat.pbrMetallicRoughness.roughnessFactor), kPaperRoughness);
    EXPECT_EQ(mat.pbrMetallicRoughness.baseColorFactor, (std::vector<double>{1, 1, 1, 1}));
    if (haveReceiptTexture()) {
      ASSERT_EQ(mat.pbrMetallicRoughness.baseColorTexture.index, 0);
      ASSERT_EQ(m.images.size(), 1u);
      const auto& img = m.images[0];
      EXPECT_EQ(img.mimeType, "image/png");
      EXPECT_EQ(img.width, 512); // decoded by the loader
      EXPECT_EQ(img.height, 768);
      EXPECT_EQ(img.image.size(), size_t(512) * 768 * size_t(img.component));
    }
  }
}

TEST(Gltf, FramesBecomeMorphTargetsWithAStepAnimation) {
  const SheetTopology topo = smallSheet();
  std::vector<MeshFrame> frames;
  for (int k = 0; k < 4; ++k) {
    SimState s = sheetState(topo);
    for (auto& p : s.pos) p.y -= 0.5f * float(k), p.z += 0.01f * float(k) * p.x;
    s.triangle_count -= uint32_t(3 * k); // tearing removes triangles, never particles
    frames.push_back(meshFrame(s, double(k) / 30.0));
  }
  MeshScene scene;
  scene.uv = topo.uv;
  std::string error;
  auto bytes = encodeGltf(scene, frames, true, error);
  ASSERT_TRUE(bytes) << error;
  tinygltf::Model m = load(*bytes, true);
  const auto& mesh = m.meshes.at(0);
  const auto& prim = mesh.primitives.at(0);
  ASSERT_EQ(prim.targets.size(), 3u);
  EXPECT_EQ(mesh.weights, (std::vector<double>{0, 0, 0}));
  EXPECT_EQ(m.accessors[size_t(prim.indices)].count, size_t(frames.back().triangles.size()) * 3); // the last set
  auto base = floats(m, prim.attributes.at("POSITION"));
  for (size_t k = 1; k < frames.size(); ++k) {
    const int target = prim.targets[k - 1].at("POSITION");
    expectBounds(m, target);
    auto d = floats(m, target);
    for (size_t i = 0; i < frames[k].pos.size(); ++i)
      EXPECT_NEAR(base[i * 3 + 1] + d[i * 3 + 1], frames[k].pos[i].y, 1e-5f);
    EXPECT_TRUE(prim.targets[k - 1].count("NORMAL"));
  }
  ASSERT_EQ(m.animations.size(), 1u);
  const auto& anim = m.animations[0];
  ASSERT_EQ(anim.channels.size(), 1u);
  EXPECT_EQ(anim.channels[0].target_path, "weights");
  EXPECT_EQ(anim.channels[0].target_node, 0);
  const auto& sampler = anim.samplers.at(size_t(anim.channels[0].sampler));
  EXPECT_EQ(sampler.interpolation, "STEP");
  auto times = floats(m, sampler.input);
  ASSERT_EQ(times.size(), 4u);
  EXPECT_EQ(times[0], 0.0f);
  EXPECT_FLOAT_EQ(times[3], 0.1f);
  auto w = floats(m, sampler.output);
  ASSERT_EQ(w.size(), 4u * 3u);
  for (size_t k = 0; k < 4; ++k)
    for (size_t t = 0; t < 3; ++t) EXPECT_EQ(w[k * 3 + t], k == t + 1 ? 1.0f : 0.0f) << k << " " << t;
}

TEST(Gltf, EveryTriangleTornLeavesPoints) {
  const SheetTopology topo = smallSheet();
  SimState s = sheetState(topo);
  s.triangle_count = 0;
  std::string error;
  auto bytes = encodeGltf(MeshScene{topo.uv, {}, "receipt"}, {meshFrame(s, 0.0)}, true, error);
  ASSERT_TRUE(bytes) << error;
  tinygltf::Model m = load(*bytes, true);
  EXPECT_EQ(m.meshes.at(0).primitives.at(0).mode, TINYGLTF_MODE_POINTS);
  EXPECT_EQ(m.meshes.at(0).primitives.at(0).indices, -1);
}

} // namespace
} // namespace tender
