#include "gltf.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

#include <stb/stb_image_write.h>
#include <tiny_gltf.h>

namespace shaderio {
using namespace glm;
#include "render_types.h"
} // namespace shaderio

#ifdef TENDER_HAS_RECEIPT
#include "render/receipt.h"
#endif

namespace tender {
namespace {

// glTF enumerations (the specification's numbers).
constexpr int kArrayBuffer = 34962;
constexpr int kElementArrayBuffer = 34963;
constexpr int kLinear = 9729;
constexpr int kLinearMipmapLinear = 9987;
constexpr int kClampToEdge = 33071;

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

// A finite copy of a position (a non-finite coordinate, which a healthy run never has, becomes 0:
// a glTF accessor may hold no NaN).
glm::vec3 finite(glm::vec3 p) {
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(p[k])) p[k] = 0.0f;
  return p;
}

// A unit normal: the normals pass gives one per particle; a zero or broken one becomes +z.
glm::vec3 unitNormal(glm::vec3 n) {
  float len = glm::length(n);
  if (!std::isfinite(len) || len < 1e-12f) return glm::vec3(0.0f, 0.0f, 1.0f);
  return n / len;
}

// Builds the model: one buffer, views appended 4-byte aligned.
class Builder {
public:
  explicit Builder(tinygltf::Model& m) : m_(m) { m_.buffers.emplace_back(); }

  int view(const void* data, size_t bytes, int target) {
    auto& buf = m_.buffers[0].data;
    while (buf.size() % 4) buf.push_back(0);
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = buf.size();
    v.byteLength = bytes;
    v.target = target;
    auto p = static_cast<const unsigned char*>(data);
    buf.insert(buf.end(), p, p + bytes);
    m_.bufferViews.push_back(v);
    return int(m_.bufferViews.size() - 1);
  }

  // A VEC3 float accessor with its min and max.
  int vec3(const std::vector<glm::vec3>& v) {
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(std::numeric_limits<float>::lowest());
    for (const glm::vec3& p : v) lo = glm::min(lo, p), hi = glm::max(hi, p);
    tinygltf::Accessor a = accessor(view(v.data(), v.size() * sizeof(glm::vec3), kArrayBuffer), v.size(),
                                    TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3);
    a.minValues = {lo.x, lo.y, lo.z};
    a.maxValues = {hi.x, hi.y, hi.z};
    return push(a);
  }

  int vec2(const std::vector<glm::vec2>& v) {
    return push(accessor(view(v.data(), v.size() * sizeof(glm::vec2), kArrayBuffer), v.size(),
                         TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2));
  }

  int indices(const std::vector<uint32_t>& idx) {
    tinygltf::Accessor a = accessor(view(idx.data(), idx.size() * 4, kElementArrayBuffer), idx.size(),
                                    TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR);
    a.minValues = {double(*std::min_element(idx.begin(), idx.end()))};
    a.maxValues = {double(*std::max_element(idx.begin(), idx.end()))};
    return push(a);
  }

  // Scalar floats of animation data (no buffer target: not vertex data).
  int scalars(const std::vector<float>& v, bool with_range) {
    tinygltf::Accessor a =
        accessor(view(v.data(), v.size() * 4, 0), v.size(), TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_SCALAR);
    if (with_range) {
      a.minValues = {*std::min_element(v.begin(), v.end())};
      a.maxValues = {*std::max_element(v.begin(), v.end())};
    }
    return push(a);
  }

private:
  static tinygltf::Accessor accessor(int view, size_t count, int component, int type) {
    tinygltf::Accessor a;
    a.bufferView = view;
    a.byteOffset = 0;
    a.count = count;
    a.componentType = component;
    a.type = type;
    return a;
  }
  int push(const tinygltf::Accessor& a) {
    m_.accessors.push_back(a);
    return int(m_.accessors.size() - 1);
  }

  tinygltf::Model& m_;
};

std::vector<glm::vec3> positions(const MeshFrame& f) {
  std::vector<glm::vec3> out(f.pos.size());
  for (size_t i = 0; i < f.pos.size(); ++i) out[i] = finite(glm::vec3(f.pos[i]));
  return out;
}

std::vector<glm::vec3> normals(const MeshFrame& f, size_t n) {
  std::vector<glm::vec3> out(n, glm::vec3(0.0f, 0.0f, 1.0f));
  for (size_t i = 0; i < n && i < f.normal.size(); ++i) out[i] = unitNormal(glm::vec3(f.normal[i]));
  return out;
}

constexpr uint32_t kNoTriangle = 0xFFFFFFFFu;

/// The vertices of the export: one per particle, and one more for each corner of a triangle that
/// takes the triangle's own normal across a crease in some frame (shaderio::cornerNormal, as the
/// renderer shades it); `corner` holds each triangle corner's vertex.
struct CreaseVertices {
  std::vector<uint32_t> particle; ///< the particle of each vertex
  std::vector<uint32_t> triangle; ///< the triangle of a corner's own vertex; kNoTriangle: a particle's
  std::vector<uint32_t> corner;   ///< vertex of corner 3 t + c of the last frame's triangles
};

glm::vec3 cornerNormalOf(const std::vector<glm::vec3>& p, const std::vector<glm::vec3>& nn, glm::uvec3 t, uint32_t i) {
  return shaderio::cornerNormal(nn[i], p[t.x], p[t.y], p[t.z]);
}

CreaseVertices creaseVertices(const std::vector<glm::uvec3>& triangles, const std::vector<std::vector<glm::vec3>>& pos,
                              const std::vector<std::vector<glm::vec3>>& nrm, size_t n) {
  CreaseVertices v;
  v.particle.resize(n);
  v.triangle.assign(n, kNoTriangle);
  for (size_t i = 0; i < n; ++i) v.particle[i] = uint32_t(i);
  v.corner.resize(triangles.size() * 3);
  for (size_t t = 0; t < triangles.size(); ++t)
    for (uint32_t c = 0; c < 3; ++c) {
      const uint32_t i = triangles[t][int(c)];
      bool split = false;
      for (size_t f = 0; f < pos.size() && !split; ++f)
        split = cornerNormalOf(pos[f], nrm[f], triangles[t], i) != nrm[f][i];
      v.corner[t * 3 + c] = split ? uint32_t(v.particle.size()) : i;
      if (split) v.particle.push_back(i), v.triangle.push_back(uint32_t(t));
    }
  return v;
}

/// Per vertex of `v`: the position and the normal of one frame.
void frameVertices(const CreaseVertices& v, const std::vector<glm::uvec3>& triangles, const std::vector<glm::vec3>& p,
                   const std::vector<glm::vec3>& nn, std::vector<glm::vec3>& pos_out,
                   std::vector<glm::vec3>& normal_out) {
  pos_out.resize(v.particle.size());
  normal_out.resize(v.particle.size());
  for (size_t k = 0; k < v.particle.size(); ++k) {
    const uint32_t i = v.particle[k];
    pos_out[k] = p[i];
    normal_out[k] = v.triangle[k] == kNoTriangle ? nn[i] : cornerNormalOf(p, nn, triangles[v.triangle[k]], i);
  }
}

/// What makes `frames` no glTF file: none, no particles, a particle count that changes, a triangle
/// beyond the sheet, or frame times that do not increase.
std::optional<std::string> frameProblem(const std::vector<MeshFrame>& frames) {
  if (frames.empty()) return "glTF export: no frame to write";
  const size_t n = frames.front().pos.size();
  if (n == 0) return "glTF export: the sheet has no particles";
  for (const MeshFrame& f : frames)
    if (f.pos.size() != n) return "glTF export: the particle count changed between frames";
  for (const glm::uvec3& t : frames.back().triangles)
    if (t.x >= n || t.y >= n || t.z >= n) return "glTF export: a triangle names a particle beyond the sheet";
  for (size_t k = 1; k < frames.size(); ++k)
    if (!(float(frames[k].time) > float(frames[k - 1].time))) return "glTF export: frame times must increase";
  return std::nullopt;
}

/// The renderer's paper as material 0: white times the receipt, roughness 0.7, no metal, both faces.
void addPaperMaterial(tinygltf::Model& m, Builder& b, const MeshScene& scene) {
  tinygltf::Material mat;
  mat.name = "receipt paper";
  mat.doubleSided = true;
  mat.pbrMetallicRoughness.baseColorFactor = {1.0, 1.0, 1.0, 1.0};
  mat.pbrMetallicRoughness.metallicFactor = 0.0;
  mat.pbrMetallicRoughness.roughnessFactor = kPaperRoughness;
  if (!scene.texture_png.empty()) {
    tinygltf::Image img;
    img.name = "receipt";
    img.mimeType = "image/png";
    img.bufferView = b.view(scene.texture_png.data(), scene.texture_png.size(), 0);
    m.images.push_back(img);
    tinygltf::Sampler s;
    s.magFilter = kLinear;
    s.minFilter = kLinearMipmapLinear;
    s.wrapS = kClampToEdge;
    s.wrapT = kClampToEdge;
    m.samplers.push_back(s);
    tinygltf::Texture tex;
    tex.sampler = 0;
    tex.source = 0;
    m.textures.push_back(tex);
    mat.pbrMetallicRoughness.baseColorTexture.index = 0;
  }
  m.materials.push_back(mat);
}

/// Animation: frame k > 0 is morph target k - 1 (position and normal deltas from the first
/// frame), shown alone by a step-interpolated weights track.
void addMorphAnimation(tinygltf::Model& m, Builder& b, const std::vector<MeshFrame>& frames, const CreaseVertices& cv,
                       const std::vector<std::vector<glm::vec3>>& pos, const std::vector<std::vector<glm::vec3>>& nrm,
                       const std::vector<glm::vec3>& base_pos, const std::vector<glm::vec3>& base_normal,
                       tinygltf::Primitive& prim, tinygltf::Mesh& mesh) {
  const MeshFrame& last = frames.back();
  const size_t targets = frames.size() - 1;
  if (targets == 0) return;
  for (size_t k = 1; k < frames.size(); ++k) {
    std::vector<glm::vec3> dp, dn;
    frameVertices(cv, last.triangles, pos[k], nrm[k], dp, dn);
    for (size_t i = 0; i < dp.size(); ++i) dp[i] -= base_pos[i], dn[i] -= base_normal[i];
    prim.targets.push_back({{"POSITION", b.vec3(dp)}, {"NORMAL", b.vec3(dn)}});
  }
  mesh.weights.assign(targets, 0.0);
  std::vector<float> times(frames.size());
  for (size_t k = 0; k < frames.size(); ++k) times[k] = float(frames[k].time);
  std::vector<float> weights(frames.size() * targets, 0.0f);
  for (size_t k = 1; k < frames.size(); ++k) weights[k * targets + (k - 1)] = 1.0f;
  tinygltf::AnimationSampler s;
  s.input = b.scalars(times, true);
  s.output = b.scalars(weights, false);
  s.interpolation = "STEP";
  tinygltf::AnimationChannel c;
  c.sampler = 0;
  c.target_node = 0;
  c.target_path = "weights";
  tinygltf::Animation anim;
  anim.name = "simulation";
  anim.samplers.push_back(s);
  anim.channels.push_back(c);
  m.animations.push_back(anim);
}

} // namespace

std::optional<MeshFormat> meshFormatFor(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  const size_t dot = name.find_last_of('.');
  if (dot == std::string::npos || dot == 0) return MeshFormat::Ply;
  const std::string ext = lower(name.substr(dot));
  if (ext == ".ply") return MeshFormat::Ply;
  if (ext == ".glb") return MeshFormat::Glb;
  if (ext == ".gltf") return MeshFormat::Gltf;
  return std::nullopt;
}

MeshFrame meshFrame(const SimState& state, double time) {
  MeshFrame f;
  f.time = time;
  f.pos = state.pos;
  f.normal = state.normal;
  const uint32_t n = std::min<uint32_t>(state.triangle_count, uint32_t(state.triangles.size()));
  f.triangles.reserve(n);
  for (uint32_t k = 0; k < n; ++k) f.triangles.emplace_back(glm::uvec3(state.triangles[k]));
  return f;
}

std::optional<std::string> encodeGltf(const MeshScene& scene, const std::vector<MeshFrame>& frames, bool binary,
                                      std::string& error) {
  if (auto why = frameProblem(frames)) {
    error = *why;
    return std::nullopt;
  }
  const MeshFrame& last = frames.back();
  const size_t n = last.pos.size();

  tinygltf::Model m;
  m.asset.version = "2.0";
  m.asset.generator = std::string("Tender ") + TENDER_VERSION;
  Builder b(m);

  // Geometry: the first frame's particles, the last frame's triangles; a corner across a crease
  // has a vertex of its own with its triangle's normal (as the renderer shades it).
  std::vector<std::vector<glm::vec3>> pos(frames.size()), nrm(frames.size());
  for (size_t k = 0; k < frames.size(); ++k) pos[k] = positions(frames[k]), nrm[k] = normals(frames[k], n);
  const CreaseVertices cv = creaseVertices(last.triangles, pos, nrm, n);
  std::vector<glm::vec3> base_pos, base_normal;
  frameVertices(cv, last.triangles, pos[0], nrm[0], base_pos, base_normal);
  tinygltf::Primitive prim;
  prim.attributes["POSITION"] = b.vec3(base_pos);
  prim.attributes["NORMAL"] = b.vec3(base_normal);
  std::vector<glm::vec2> uv(cv.particle.size(), glm::vec2(0.0f));
  for (size_t k = 0; k < uv.size(); ++k)
    if (cv.particle[k] < scene.uv.size()) uv[k] = scene.uv[cv.particle[k]];
  prim.attributes["TEXCOORD_0"] = b.vec2(uv);
  if (!last.triangles.empty()) {
    prim.indices = b.indices(cv.corner);
    prim.mode = TINYGLTF_MODE_TRIANGLES;
  } else {
    prim.mode = TINYGLTF_MODE_POINTS; // every triangle torn: the particles alone
  }

  addPaperMaterial(m, b, scene);
  prim.material = 0;

  tinygltf::Mesh mesh;
  mesh.name = scene.name;

  addMorphAnimation(m, b, frames, cv, pos, nrm, base_pos, base_normal, prim, mesh);
  mesh.primitives.push_back(prim);
  m.meshes.push_back(mesh);

  tinygltf::Node node;
  node.name = scene.name;
  node.mesh = 0;
  m.nodes.push_back(node);
  tinygltf::Scene sc;
  sc.nodes = {0};
  m.scenes.push_back(sc);
  m.defaultScene = 0;
  m.buffers[0].name = "sheet";

  std::ostringstream out;
  tinygltf::TinyGLTF gltf;
  if (!gltf.WriteGltfSceneToStream(&m, out, false, binary) || !out) {
    error = "glTF export: cannot encode the file";
    return std::nullopt;
  }
  return out.str();
}

bool haveReceiptTexture() {
#ifdef TENDER_HAS_RECEIPT
  return true;
#else
  return false;
#endif
}

std::string receiptPng(const std::string& preset) {
#ifdef TENDER_HAS_RECEIPT
  // The layout's own size: a small file that reads well in a viewer (the renderer prints larger)
  const render::ReceiptImage img = render::rasterizeReceipt(render::receiptText(preset), render::kReceiptLayoutWidth);
  std::string bytes;
  stbi_write_png_to_func(
      [](void* context, void* data, int size) {
        static_cast<std::string*>(context)->append(static_cast<char*>(data), size_t(size));
      },
      &bytes, int(img.width), int(img.height), 4, img.rgba.data(), int(img.width * 4));
  return bytes;
#else
  (void)preset;
  return {};
#endif
}

} // namespace tender
