#pragma once
/// Helpers of every test that drives a Simulation, whatever the backend: parameters of a preset
/// with overrides, input scripts, running and reading back.
#include <gtest/gtest.h>

#include <cstring>
#include <initializer_list>
#include <sstream>
#include <string>
#include <vector>

#include "core/params.h"
#include "core/script.h"
#include "core/simulation.h"

/// Marks a test whose scenes run the CPU solver on one thread (CpuOptions' default) and nothing
/// else concurrently. ThreadSanitizer reports races between threads, so there it has nothing to
/// find, and at its tenfold cost the physics repeats the ci and ASan builds' runs; the tsan build
/// skips such a test, saying why. Every other build runs it.
#if defined(__SANITIZE_THREAD__) // GCC; Clang says so through __has_feature
#define TENDER_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define TENDER_TSAN 1
#endif
#endif
#if defined(TENDER_TSAN)
#define TENDER_ONE_THREAD_TEST() GTEST_SKIP() << "one thread: no race for ThreadSanitizer to find"
#else
#define TENDER_ONE_THREAD_TEST() static_cast<void>(0)
#endif

namespace tender::test {

/// False in the tsan build: a test that compares a run on one thread with the same run on several
/// runs only the threaded one there, for ThreadSanitizer to judge (the one-thread run has nothing
/// for it to find); the ci and ASan builds compare their bits.
#if defined(TENDER_TSAN)
inline constexpr bool kComparesThreadCounts = false;
#else
inline constexpr bool kComparesThreadCounts = true;
#endif

/// `p` with overrides (which must be valid).
inline SimParams withSets(SimParams p, const std::vector<std::string>& sets) {
  for (const std::string& s : sets) {
    auto err = applyOverride(p, s);
    EXPECT_FALSE(err) << *err;
  }
  auto err = validate(p);
  EXPECT_FALSE(err) << *err;
  return p;
}

/// Parameters of a preset with overrides (which must be valid).
inline SimParams preset(const std::string& name, const std::vector<std::string>& sets) {
  return withSets(*presetParams(name), sets);
}
inline SimParams preset(const char* name, std::initializer_list<const char*> sets = {}) {
  return preset(std::string(name), std::vector<std::string>(sets.begin(), sets.end()));
}

/// The seeds' cloth as SimParams' defaults give it (the sheet hanging from its pins with the
/// particle repulsion, no contact), with `sets` over it: a test scene that no preset file changes.
inline SimParams cloth(std::initializer_list<const char*> sets = {}) {
  return withSets(SimParams{}, std::vector<std::string>(sets.begin(), sets.end()));
}

/// SimParams' defaults with the space-separated `keys` and then `sets` over them (which must be
/// valid): a test scene that names every key it depends on, so that no preset file changes it.
inline SimParams keyed(const std::string& keys, const std::vector<std::string>& sets) {
  std::vector<std::string> all;
  std::istringstream words(keys);
  for (std::string key; words >> key;) all.push_back(key);
  all.insert(all.end(), sets.begin(), sets.end());
  return withSets(SimParams{}, all);
}
inline SimParams keyed(const std::string& keys, std::initializer_list<const char*> sets) {
  return keyed(keys, std::vector<std::string>(sets.begin(), sets.end()));
}

/// Contact as every preset has it (contact_factor) and the settle's sweeps of the paper's presets.
inline constexpr const char* kContactKeys = "contact_factor=0.5";
inline const std::string kSettleKeys = std::string(kContactKeys) + " contact_settle=16";

/// The seeds' cloth with contact (the `tender` preset's scene, every key named), with `sets` over it.
inline SimParams clothWithContact(std::initializer_list<const char*> sets = {}) { return keyed(kContactKeys, sets); }

/// A 40 x 60 sheet of paper hanging from its corners, without contact, with `sets` over it: hinges
/// that crease and the stretch limit at the scale of the hand's scenes (the `crumple` preset's
/// paper).
inline constexpr const char* kPaperKeys =
    "cols=40 rows=60 spacing=0.15 pins=corners bend=off dihedral=on tick_hz=60 substeps=8 iterations=4 "
    "gravity=0.5 damping=0.995 wind=off wind_kind=noise wind_scale=0.15 bending_rigidity=0.02 "
    "crease_yield=11.5 crease_hardening=0.5 stretch_limit=1.01 cell_size=0.375 floor_y=-10 "
    "restitution=0.3 friction=0.3 release=drag";
inline SimParams paperSheet(std::initializer_list<const char*> sets = {}) { return keyed(kPaperKeys, sets); }

/// The paper of the hand's scenes with contact and the settle's sweeps (the `crumple` preset's
/// scene, every key named), with `sets` over it.
inline SimParams crumpleSheet(std::initializer_list<const char*> sets = {}) {
  return keyed(std::string(kPaperKeys) + " " + kSettleKeys, sets);
}

/// A receipt in SI units without contact, with `sets` over it: 80 mm x 300 mm of 55 g/m^2 paper in
/// still air, its lowest point 1 m above the floor, leaning 5 degrees from flat (the `paper`
/// preset's sheet).
inline constexpr const char* kReceiptKeys =
    "cols=17 rows=61 spacing=0.005 pins=none tilt=85 view_scale=0.1 bend=off dihedral=on damping=1 "
    "wind=off air=on paper_weight=55 bending_rigidity=7.9e-05 crease_yield=11.5 crease_hardening=0.5 "
    "stretch_limit=1.01 cell_size=0.012499999 floor_y=0 restitution=0.05 friction=0.6 release=drag "
    "grab_radius=0.02 hand_reach=0.16";
inline SimParams receiptSheet(std::initializer_list<const char*> sets = {}) { return keyed(kReceiptKeys, sets); }

/// The receipt with contact and the settle's sweeps (the `paper` preset's scene, every key named),
/// with `sets` over it.
inline SimParams receiptWithContact(const std::vector<std::string>& sets) {
  return keyed(std::string(kReceiptKeys) + " " + kSettleKeys, sets);
}
inline SimParams receiptWithContact(std::initializer_list<const char*> sets = {}) {
  return receiptWithContact(std::vector<std::string>(sets.begin(), sets.end()));
}

/// Parses an input script (which must be valid).
inline InputScript script(const char* text) {
  std::string err;
  auto s = parseScript(text, err);
  EXPECT_TRUE(s) << err;
  return s ? *s : InputScript{};
}

/// Ticks the simulation, recomputes the normals and reads the state back.
inline SimState run(Simulation& sim, int ticks) {
  for (int t = 0; t < ticks; ++t) sim.tick();
  SimState s;
  sim.solver().computeNormals();
  sim.solver().readback(s);
  return s;
}

/// Number of torn constraints.
inline uint32_t tornCount(const SimState& s) {
  uint32_t n = 0;
  for (uint32_t t : s.torn) n += t != 0u ? 1u : 0u;
  return n;
}

/// Live constraints whose two particles lie in different pieces of the live triangle mesh (a
/// particle no live triangle holds is a piece of its own): what would tie torn-apart pieces
/// together. Judged from the state alone, by a union-find over the live triangles' corners.
inline uint32_t tiesAcrossPieces(const SimState& s) {
  std::vector<uint32_t> piece(s.pos.size());
  for (uint32_t i = 0; i < piece.size(); ++i) piece[i] = i;
  auto find = [&](uint32_t x) {
    while (piece[x] != x) x = piece[x] = piece[piece[x]];
    return x;
  };
  for (uint32_t t = 0; t < s.triangle_count; ++t) {
    piece[find(s.triangles[t].x)] = find(s.triangles[t].y);
    piece[find(s.triangles[t].y)] = find(s.triangles[t].z);
  }
  uint32_t ties = 0;
  for (const ColorRange& range : s.colors)
    for (uint32_t k = range.first; k < range.first + range.count; ++k)
      ties += find(s.constraints[k].a) != find(s.constraints[k].b) ? 1u : 0u;
  return ties;
}

/// True when two arrays hold the same bytes (and are the same size).
template <typename T>
bool sameBytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

} // namespace tender::test
