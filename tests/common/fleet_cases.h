#pragma once
/// The fleet cases every backend runs: a batch of sheets with mixed parameters and scripts, each
/// compared bitwise with the same sheet run alone on that backend.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "common/sim_helpers.h"
#include "core/fleet.h"

namespace tender::test {

/// Sheets of a cols x rows grid (12 x 16: small enough for the fused tick); sheet i takes its
/// parameters and its script from i, so a batch of 37 holds every combination below several times:
/// tearing yanks and sheets left hanging, a reset, a pause, a ray grab and a hand closing around it, three pin modes,
/// both winds, and different stiffness, damping, gravity, tear factor, restitution, floor, substeps, iterations,
/// release, collision, air, stretch limit and hash cell (sheets 5, 13, ... have cells of 5 spacings, which a CPU
/// device's fused tick does not take).
inline std::vector<FleetSheet> mixedFleet(uint32_t count, uint32_t cols = 12, uint32_t rows = 16) {
  static const char* kScripts[] = {
      "",
      // A hard yank: tears unless the tear factor is high
      "0 grab particle 186\n1 move 4 -4 6\n30 release\n",
      // A grab, a reset while the sheet swings, then a pause
      "0 grab particle 100\n2 move 1 0 1\n10 release\n15 reset\n50 pause on\n54 pause off\n",
      // A ray grab from in front of the sheet, dragged sideways while the hand closes around it
      "3 grab ray 0 1 5 0 0 -1\n4 move 2 1 2\n6 squeeze 0.5\n10 squeeze 1\n20 release\n",
  };
  static const char* kPins[] = {"top3", "corners", "none"};
  std::vector<FleetSheet> sheets;
  for (uint32_t i = 0; i < count; ++i) {
    std::vector<std::string> sets = {
        "cols=" + std::to_string(cols),
        "rows=" + std::to_string(rows),
        "spacing=0.16",
        std::string("pins=") + kPins[i % 3],
        std::string("wind_kind=") + (i % 2 ? "noise" : "sinusoid"),
        "wind_strength=" + std::to_string(0.5 + 0.25 * (i % 5)),
        "damping=" + std::to_string(0.97 + 0.005 * (i % 4)),
        "gravity=" + std::to_string(8.0 + 0.5 * (i % 6)),
        "stiffness=" + std::to_string(0.7 + 0.1 * (i % 4)),
        "tear_factor=" + std::string(i % 7 == 3   ? "0"
                                     : i % 5 == 2 ? "6"
                                                  : "2.5"),
        "restitution=" + std::to_string(0.1 * (i % 3)),
        "floor_y=" + std::to_string(-2.0 - 0.5 * (i % 3)),
        "substeps=" + std::to_string(6 + i % 3),
        "iterations=" + std::to_string(3 + i % 2),
        std::string("release=") + (i % 4 == 1 ? "drag" : "zero"),
        std::string("collision=") + (i % 9 == 4 ? "off" : "on"),
        std::string("air=") + (i % 5 == 1 ? "on" : "off"),
        std::string("cell_size=") + (i % 8 == 5 ? "0.8" : "0.4"),
        std::string("stretch_limit=") + ((i / 2) % 3 == 0   ? "0"
                                         : (i / 2) % 3 == 1 ? "1.01"
                                                            : "1.05"),
    };
    FleetSheet s;
    s.params = withSets(SimParams{}, sets); // the seeds' cloth (with contact: withContact in fleet_test.cpp)
    s.script = script(kScripts[i % 4]);
    sheets.push_back(std::move(s));
  }
  return sheets;
}

/// A fleet of `count` sheets of paper without contact: paperSheet's paper on a 12 x 16 sheet (hinges,
/// creases, the stretch limit) lying on its floor, free or pinned at its corners, folded, crumpled
/// by the hand and yanked; or, with `receipt`, receiptSheet falling through the air and folded.
inline std::vector<FleetSheet> paperFleet(uint32_t count, bool receipt = false) {
  static const char* kSheetScripts[] = {
      "",
      // A fold: the far edge lifted over the sheet and pressed down
      "0 grab particle 186\n3 move 0.1 -9 -2\n6 move 0.1 -9.8 -0.2\n15 release\n",
      // The hand closing around the middle
      "0 grab particle 102\n1 move 0 -8.8 -1.2\n3 squeeze 0.5\n6 squeeze 1\n12 move 1 -8 -1\n15 release\n",
      // A yank
      "0 grab particle 186\n1 move 3 -6 4\n10 release\n",
  };
  static const char* kReceiptScripts[] = {"", "2 grab particle 1020\n3 move 0.05 0.9 0.1\n10 release\n"};
  std::vector<FleetSheet> sheets;
  for (uint32_t i = 0; i < count; ++i) {
    std::vector<std::string> sets = {
        std::string("crease_yield=") + (i % 3 == 0   ? "0"
                                        : i % 3 == 1 ? "5"
                                                     : "11.5"),
        std::string("stretch_limit=") + (i % 4 == 3   ? "0"
                                         : i % 4 == 1 ? "1.05"
                                                      : "1.01"),
        "crease_hardening=" + std::to_string(0.25 * (i % 3)),
        "iterations=" + std::to_string(3 + i % 2),
    };
    if (receipt) {
      sets.push_back(std::string("air=") + (i % 5 == 4 ? "off" : "on"));
    } else {
      // (the rest lengths come from the start: every sheet of a fleet lies flat)
      for (const char* s : {"cols=12", "rows=16", "wind=off", "tilt=90", "top_y=-9.9"}) sets.push_back(s);
      sets.push_back(std::string("pins=") + (i % 5 == 4 ? "corners" : "none"));
      sets.push_back(std::string("tear_factor=") + (i % 6 == 5 ? "0" : "2.5"));
    }
    FleetSheet s;
    s.params = withSets(receipt ? receiptSheet() : paperSheet(), sets); // without contact
    s.script = script(receipt ? kReceiptScripts[i % 2] : kSheetScripts[i % 4]);
    sheets.push_back(std::move(s));
  }
  return sheets;
}

/// Runs a fleet of `sheets` on `batch` for `ticks` steps and each sheet alone on `alone`, and
/// expects every sheet's state to be bitwise the same both ways (normals aside: a fleet on the GPU
/// computes them on the host). Returns the number of sheets that tore.
inline uint32_t expectFleetMatchesAlone(SheetBatch& batch, Solver& alone, const std::vector<FleetSheet>& sheets,
                                        int ticks) {
  Fleet fleet(batch, sheets);
  for (int t = 0; t < ticks; ++t) fleet.tick();
  // Every sheet's positions in one read-back, as each sheet's own read-back gives them
  std::vector<glm::vec4> all_pos, all_prev;
  batch.readPositions(all_pos, all_prev);
  const size_t n = fleet.sim(0).topology().particleCount();
  EXPECT_EQ(all_pos.size(), n * sheets.size());
  EXPECT_EQ(all_prev.size(), n * sheets.size());
  uint32_t tore = 0;
  for (uint32_t i = 0; i < sheets.size(); ++i) {
    SimState a, b;
    fleet.sim(i).solver().readback(a);
    if (all_pos.size() == n * sheets.size()) {
      EXPECT_TRUE(sameBytes(a.pos, std::vector<glm::vec4>(all_pos.begin() + i * n, all_pos.begin() + (i + 1) * n)));
      EXPECT_TRUE(sameBytes(a.prev, std::vector<glm::vec4>(all_prev.begin() + i * n, all_prev.begin() + (i + 1) * n)));
    }
    Simulation sim(sheets[i].params, alone);
    sim.setScript(sheets[i].script);
    b = run(sim, ticks);
    // Two empty read-backs are no evidence of equal runs (triangles and torn flags may be empty).
    EXPECT_EQ(a.pos.size(), n) << "sheet " << i;
    EXPECT_FALSE(a.prev.empty() || a.constraints.empty()) << "sheet " << i;
    EXPECT_EQ(fleet.sim(i).grabCount(), sim.grabCount()) << "sheet " << i;
    EXPECT_EQ(fleet.sim(i).solver().contacts(), alone.contacts()) << "sheet " << i;
    EXPECT_TRUE(sameBytes(a.pos, b.pos)) << "sheet " << i;
    EXPECT_TRUE(sameBytes(a.prev, b.prev)) << "sheet " << i;
    EXPECT_TRUE(sameBytes(a.constraints, b.constraints)) << "sheet " << i;
    EXPECT_TRUE(sameBytes(a.colors, b.colors)) << "sheet " << i;
    EXPECT_TRUE(sameBytes(a.torn, b.torn)) << "sheet " << i;
    EXPECT_TRUE(sameBytes(a.hinges, b.hinges)) << "sheet " << i;
    EXPECT_TRUE(sameBytes(a.triangles, b.triangles)) << "sheet " << i;
    uint32_t torn = 0;
    for (uint32_t k : a.torn) torn += k;
    tore += torn > 0 ? 1u : 0u;
  }
  return tore;
}

} // namespace tender::test
