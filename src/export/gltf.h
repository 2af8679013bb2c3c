#pragma once
/// The sheet as glTF 2.0: positions, normals, receipt UVs, the triangles that remain, the receipt
/// texture (PNG, embedded) and a double-sided matte material like the renderer's. Several frames
/// make one animated file: morph targets (one per frame after the first) driven by a
/// step-interpolated weights animation.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/solver.h"

namespace tender {

/// What `--out` writes, picked by the path's extension.
enum class MeshFormat { Ply, Glb, Gltf };

/// The format of an output path: `.glb`, `.gltf`, `.ply` (any case), and PLY for a path with no
/// extension (a device such as /dev/stdout); nullopt for any other extension.
std::optional<MeshFormat> meshFormatFor(const std::string& path);

/// One frame of an export: the particles (all of them; tearing never removes particles) and the
/// triangles alive in that frame.
struct MeshFrame {
  double time = 0.0;             ///< seconds from the start (tick / tick_hz)
  std::vector<glm::vec4> pos;    ///< xyz used
  std::vector<glm::vec4> normal; ///< xyz used, normalised on export (a zero normal becomes +z)
  std::vector<glm::uvec3> triangles;
};

/// The frame of a read-back state at `time`.
MeshFrame meshFrame(const SimState& state, double time);

/// What every frame shares.
struct MeshScene {
  std::vector<glm::vec2> uv; ///< per particle
  std::string texture_png;   ///< the receipt as PNG bytes; empty: the material has no texture
  std::string name = "receipt";
};

/// The renderer's paper material: white base colour times the receipt texture, roughness 0.7,
/// metalness 0, double-sided.
constexpr float kPaperRoughness = 0.7f;

/// Encodes `frames` (at least one) as glTF: binary (.glb) or JSON with the buffer embedded as a
/// data URI (.gltf). One frame is a static mesh; more make an animation over the particles of the
/// first frame, with morph targets for the others and the triangles of the LAST frame (what
/// remains at the end). Returns the bytes, or sets `error`.
std::optional<std::string> encodeGltf(const MeshScene& scene, const std::vector<MeshFrame>& frames, bool binary,
                                      std::string& error);

/// The receipt of a preset rasterised and encoded as PNG; empty when Tender is built without the
/// receipt rasteriser (no FreeType). Throws std::runtime_error when the font is missing.
std::string receiptPng(const std::string& preset);

/// True when receiptPng() can give a texture (built with FreeType).
bool haveReceiptTexture();

} // namespace tender
