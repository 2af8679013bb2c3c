#include "sheet.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>

namespace tender {

bool SheetTopology::adjacent(uint32_t a, uint32_t b) const {
  auto first = adj_list.begin() + adj_offsets[a], last = adj_list.begin() + adj_offsets[a + 1];
  return std::binary_search(first, last, b);
}

std::vector<uint32_t> pinIndices(PinMode mode, uint32_t cols, uint32_t /*rows*/) {
  std::vector<uint32_t> pins;
  if (mode == PinMode::Top3) pins = {0, cols / 2, cols - 1};
  if (mode == PinMode::Corners) pins = {0, cols - 1};
  std::sort(pins.begin(), pins.end());
  pins.erase(std::unique(pins.begin(), pins.end()), pins.end());
  return pins;
}

std::vector<uint32_t> colorGreedy(const std::vector<shaderio::Constraint>& cs, uint32_t cols, uint32_t rows,
                                  uint32_t hinge_first) {
  // used[i] has bit c set when particle i already has a constraint of colour c.
  std::vector<uint64_t> used(size_t(cols) * rows, 0);
  std::vector<uint32_t> color(cs.size());
  uint32_t distance_colors = 0;
  for (size_t k = 0; k < cs.size(); ++k) {
    const uint32_t id = constraintId(cs[k]);
    const bool hinge = constraintKind(cs[k]) == SIM_KIND_HINGE;
    const glm::uvec4 q = hinge ? shaderio::gridHinge(id - hinge_first, cols, rows) : glm::uvec4(cs[k].a, cs[k].b, 0, 0);
    const uint32_t corners = hinge ? 4 : 2;
    // The hinges' colours start after every colour the other kinds took.
    uint64_t busy = hinge ? (uint64_t(1) << distance_colors) - 1 : 0;
    for (uint32_t j = 0; j < corners; ++j) busy |= used[q[j]];
    if (busy == ~uint64_t(0)) throw std::runtime_error("constraint graph needs more than 64 colours");
    const uint32_t c = uint32_t(std::countr_one(busy));
    color[k] = c;
    if (!hinge) distance_colors = std::max(distance_colors, c + 1);
    for (uint32_t j = 0; j < corners; ++j) used[q[j]] |= uint64_t(1) << c;
  }
  return color;
}

std::vector<ColorRange> sortByColor(std::vector<shaderio::Constraint>& cs, const std::vector<uint32_t>& color) {
  uint32_t k = 0;
  for (uint32_t c : color) k = std::max(k, c + 1);
  std::vector<ColorRange> ranges(k);
  for (uint32_t c : color) ranges[c].count++;
  for (uint32_t c = 1; c < k; ++c) ranges[c].first = ranges[c - 1].first + ranges[c - 1].count;
  std::vector<shaderio::Constraint> sorted(cs.size());
  std::vector<uint32_t> cursor(k);
  for (uint32_t c = 0; c < k; ++c) cursor[c] = ranges[c].first;
  for (size_t i = 0; i < cs.size(); ++i) sorted[cursor[color[i]]++] = cs[i];
  cs.swap(sorted);
  return ranges;
}

SheetPlacement sheetPlacement(const SimParams& p) {
  SheetPlacement at;
  at.length = float(p.rows > 0 ? p.rows - 1 : 0) * p.spacing;
  if (p.tilt != 0.0f) {
    const float tilt = p.tilt * 0.017453292519943295f;
    at.down = std::cos(tilt);
    at.back = std::sin(tilt);
  }
  const float height = p.tilt != 0.0f ? at.length * at.down : at.length;
  // Centred on y = 1 (the camera's target), or higher when that would reach the floor.
  at.top = p.top_y != 0.0f ? p.top_y : std::max(1.0f + 0.5f * height, p.floor_y + 1.0f + height);
  return at;
}

std::vector<uint32_t> sheetSamples(const SheetTopology& t) {
  std::vector<uint32_t> samples;
  if (t.rows == 0 || t.cols == 0) return samples;
  for (uint32_t r = 0; r < 3; ++r)
    for (uint32_t c = 0; c < 3; ++c) samples.push_back((t.rows - 1) * r / 2 * t.cols + (t.cols - 1) * c / 2);
  return samples;
}

namespace {

/// The particles of sheet p in t: a portrait sheet in the XY plane, facing +Z, row 0 at the top;
/// with a tilt it leans back about its top edge. Their texture coordinates, and the pins.
void placeParticles(const SimParams& p, SheetTopology& t) {
  const uint32_t W = p.cols, H = p.rows, N = W * H;
  const float s = p.spacing;
  auto idx = [W](uint32_t i, uint32_t j) { return j * W + i; };
  const float width = float(W - 1) * s;
  const SheetPlacement at = sheetPlacement(p);
  const float top = at.top, down = at.down, back = at.back;
  t.rest_pos.resize(N);
  t.uv.resize(N);
  for (uint32_t j = 0; j < H; ++j)
    for (uint32_t i = 0; i < W; ++i) {
      const float along = float(j) * s;
      t.rest_pos[idx(i, j)] = p.tilt != 0.0f
                                  ? glm::vec4(-0.5f * width + float(i) * s, top - along * down, -along * back, 0.0f)
                                  : glm::vec4(-0.5f * width + float(i) * s, top - along, 0.0f, 0.0f);
      t.uv[idx(i, j)] = glm::vec2(W > 1 ? float(i) / float(W - 1) : 0.5f, H > 1 ? float(j) / float(H - 1) : 0.5f);
    }
  for (uint32_t pin : pinIndices(p.pins, W, H)) t.rest_pos[pin].w = 1.0f;
}

/// The adjacency of the N particles (CSR, each particle's neighbours rising) from constraints cs.
void buildAdjacency(const std::vector<shaderio::Constraint>& cs, uint32_t N, SheetTopology& t) {
  t.adj_offsets.assign(N + 1, 0);
  for (auto& c : cs) t.adj_offsets[c.a + 1]++, t.adj_offsets[c.b + 1]++;
  for (uint32_t i = 0; i < N; ++i) t.adj_offsets[i + 1] += t.adj_offsets[i];
  t.adj_list.resize(t.adj_offsets[N]);
  {
    std::vector<uint32_t> cursor(t.adj_offsets.begin(), t.adj_offsets.end() - 1);
    for (auto& c : cs) t.adj_list[cursor[c.a]++] = c.b, t.adj_list[cursor[c.b]++] = c.a;
    for (uint32_t i = 0; i < N; ++i)
      std::sort(t.adj_list.begin() + t.adj_offsets[i], t.adj_list.begin() + t.adj_offsets[i + 1]);
  }
}

/// The triangles of a W x H sheet in t: two per quad, split along (i,j)-(i+1,j+1), counter-clockwise
/// seen from +Z, with their two edges' constraint ids (h_id, v_id: each particle's row and column
/// edge).
void addTriangles(uint32_t W, uint32_t H, const std::vector<uint32_t>& h_id, const std::vector<uint32_t>& v_id,
                  SheetTopology& t) {
  auto idx = [W](uint32_t i, uint32_t j) { return j * W + i; };
  for (uint32_t j = 0; j + 1 < H; ++j)
    for (uint32_t i = 0; i + 1 < W; ++i) {
      uint32_t tl = idx(i, j), bl = idx(i, j + 1), br = idx(i + 1, j + 1), tr = idx(i + 1, j);
      uint32_t id = uint32_t(t.triangles.size());
      t.triangles.push_back({tl, bl, br, id});
      t.tri_edges.push_back({v_id[tl], h_id[bl]});
      t.triangles.push_back({tl, br, tr, id + 1});
      t.tri_edges.push_back({v_id[tr], h_id[tl]});
    }
}

} // namespace

SheetTopology buildSheet(const SimParams& p) {
  SheetTopology t;
  const uint32_t W = p.cols, H = p.rows, N = W * H;
  const float s = p.spacing;
  t.cols = W;
  t.rows = H;
  auto idx = [W](uint32_t i, uint32_t j) { return j * W + i; };

  placeParticles(p, t);

  // Constraints in generation order; the order is the original id.
  std::vector<shaderio::Constraint> cs;
  auto add = [&](uint32_t a, uint32_t b, float rest, uint32_t kind) {
    uint32_t id = uint32_t(cs.size());
    cs.push_back({a, b, rest, (id << SIM_KIND_BITS) | kind});
    t.kind_counts[kind]++;
    return id;
  };
  // Structural: horizontal then vertical; remember ids for the triangles' edges.
  std::vector<uint32_t> h_id(size_t(W) * H, ~0u), v_id(size_t(W) * H, ~0u);
  for (uint32_t j = 0; j < H; ++j)
    for (uint32_t i = 0; i + 1 < W; ++i) h_id[idx(i, j)] = add(idx(i, j), idx(i + 1, j), s, SIM_KIND_STRUCTURAL);
  for (uint32_t j = 0; j + 1 < H; ++j)
    for (uint32_t i = 0; i < W; ++i) v_id[idx(i, j)] = add(idx(i, j), idx(i, j + 1), s, SIM_KIND_STRUCTURAL);
  const float diag = s * std::sqrt(2.0f);
  if (p.shear) {
    for (uint32_t j = 0; j + 1 < H; ++j)
      for (uint32_t i = 0; i + 1 < W; ++i) add(idx(i, j), idx(i + 1, j + 1), diag, SIM_KIND_SHEAR);
    // The other diagonal spans the hinge along the first: with hinges, the sheet folds there.
    if (!p.dihedral)
      for (uint32_t j = 0; j + 1 < H; ++j)
        for (uint32_t i = 0; i + 1 < W; ++i) add(idx(i + 1, j), idx(i, j + 1), diag, SIM_KIND_SHEAR);
  }
  if (p.bend) {
    for (uint32_t j = 0; j < H; ++j)
      for (uint32_t i = 0; i + 2 < W; ++i) add(idx(i, j), idx(i + 2, j), 2.0f * s, SIM_KIND_BEND);
    for (uint32_t j = 0; j + 2 < H; ++j)
      for (uint32_t i = 0; i < W; ++i) add(idx(i, j), idx(i, j + 2), 2.0f * s, SIM_KIND_BEND);
  }
  if (p.tri_bend) {
    // Opposite vertices of the two triangles sharing each interior structural edge.
    const float r5 = s * std::sqrt(5.0f);
    for (uint32_t j = 1; j + 1 < H; ++j) // horizontal edge (i,j)-(i+1,j)
      for (uint32_t i = 0; i + 1 < W; ++i) add(idx(i, j - 1), idx(i + 1, j + 1), r5, SIM_KIND_TRIBEND);
    for (uint32_t j = 0; j + 1 < H; ++j) // vertical edge (i,j)-(i,j+1)
      for (uint32_t i = 1; i + 1 < W; ++i) add(idx(i - 1, j), idx(i + 1, j + 1), r5, SIM_KIND_TRIBEND);
  }

  if (p.dihedral) {
    // Hinges last, in gridHinge's order; a and b are the corners opposite the edge.
    t.hinge_first = uint32_t(cs.size());
    for (uint32_t k = 0; k < shaderio::hingeCount(W, H); ++k) {
      const glm::uvec4 q = shaderio::gridHinge(k, W, H);
      add(std::min(q.z, q.w), std::max(q.z, q.w), glm::length(glm::vec3(t.rest_pos[q.z] - t.rest_pos[q.w])),
          SIM_KIND_HINGE);
    }
  }

  buildAdjacency(cs, N, t);

  // Colour and sort.
  t.colors = sortByColor(cs, colorGreedy(cs, W, H, t.hinge_first));
  t.constraints = std::move(cs);

  addTriangles(W, H, h_id, v_id, t);

  uint32_t hs = 2;
  while (hs < 2 * N) hs <<= 1;
  t.hash_size = hs;
  t.contact = p.contact_factor > 0.0f;
  return t;
}

} // namespace tender
