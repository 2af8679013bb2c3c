#include <gtest/gtest.h>

#include <cstdio>

#include "core/params.h"
#include "core/script.h"
#include "core/sheet.h"

using namespace tender;

TEST(Params, PresetsCarryTheSpecValues) {
  SimParams t = *presetParams("tender");
  EXPECT_EQ(t.cols, 32u);
  EXPECT_EQ(t.rows, 48u);
  EXPECT_FLOAT_EQ(t.spacing, 0.18f);
  EXPECT_FLOAT_EQ(t.tick_hz, 120.0f);
  EXPECT_EQ(t.substeps, 8u);
  EXPECT_EQ(t.iterations, 4u);
  EXPECT_FLOAT_EQ(t.damping, 0.99f);
  EXPECT_FLOAT_EQ(t.tear_factor, 2.5f);
  EXPECT_FLOAT_EQ(t.cell_size, 0.45f);
  EXPECT_FLOAT_EQ(t.floor_y, -6.0f);
  EXPECT_TRUE(t.wind);
  SimParams c = *presetParams("crumple");
  EXPECT_EQ(c.cols * c.rows, 2400u);
  EXPECT_EQ(c.pins, PinMode::Corners);
  EXPECT_FLOAT_EQ(c.tick_hz, 60.0f);
  EXPECT_FLOAT_EQ(c.gravity, 0.5f);
  EXPECT_FLOAT_EQ(c.damping, 0.995f);
  EXPECT_FLOAT_EQ(c.floor_y, -10.0f);
  EXPECT_FLOAT_EQ(c.restitution, 0.3f);
  EXPECT_EQ(c.release, ReleaseMode::DragVelocity);
  EXPECT_EQ(c.wind_kind, WindKind::Noise);
  EXPECT_EQ(presetParams("tender-low")->cols * presetParams("tender-low")->rows, 24u * 36u);
  EXPECT_EQ(presetParams("crumple-low")->cols * presetParams("crumple-low")->rows, 30u * 45u);
  // paper: a real receipt in SI units
  const SimParams r = *presetParams("paper");
  EXPECT_NEAR(float(r.cols - 1) * r.spacing, 0.08f, 1e-6f);
  EXPECT_NEAR(float(r.rows - 1) * r.spacing, 0.30f, 1e-6f);
  EXPECT_FLOAT_EQ(r.gravity, 9.81f);
  EXPECT_TRUE(r.air);
  EXPECT_FLOAT_EQ(r.damping, 1.0f); // the air slows it, not a uniform damping
  EXPECT_EQ(r.pins, PinMode::None);
  EXPECT_FALSE(presetParams("origami"));
  for (auto& name : presetNames()) EXPECT_FALSE(validate(*presetParams(name))) << name;
  // Penetration-free contact in every preset; the seeds' cloth keeps its particle repulsion beside it
  for (auto& name : presetNames()) EXPECT_FLOAT_EQ(presetParams(name)->contact_factor, 0.5f) << name;
  EXPECT_TRUE(t.collision);
}

TEST(Params, TheBuiltInPresetsAreThePresetFilesTheyDump) {
  // Each built-in preset is a preset file (src/core/presets), read by loadPresetFile's code: its
  // dump, read back as a preset file, gives every key the same value; one that names a preset
  // starts from it, one that names none from the defaults
  ASSERT_EQ(presetNames(), (std::vector<std::string>{"tender", "crumple", "tender-low", "crumple-low", "paper"}));
  for (const BuiltinPreset& preset : builtinPresets()) {
    const SimParams p = *presetParams(preset.name);
    SimParams back = SimParams{};
    EXPECT_FALSE(applyPresetText(presetJson(p), "dump", std::nullopt, back)) << preset.name;
    EXPECT_EQ(paramValues(back), paramValues(p)) << preset.name;
    EXPECT_EQ(back.preset, p.preset);
  }
  const SimParams low = *presetParams("crumple-low"), crumple = *presetParams("crumple");
  EXPECT_EQ(low.cols, 30u);
  EXPECT_EQ(low.stretch_limit, crumple.stretch_limit); // from crumple
  EXPECT_EQ(presetParams("tender")->contact_factor, 0.5f);
  EXPECT_EQ(presetParams("tender")->cols, SimParams{}.cols); // from the defaults
  // A file's own errors name it
  SimParams p;
  EXPECT_EQ(applyPresetText("{\"preset\": \"origami\"}", "x.json", "tender", p).value_or(""),
            "x.json: unknown preset 'origami' (one of tender, crumple, tender-low, crumple-low, paper)");
}

TEST(Params, OverridesParseAndValidate) {
  SimParams p = *presetParams("tender");
  EXPECT_FALSE(applyOverride(p, "cols=64"));
  EXPECT_EQ(p.cols, 64u);
  EXPECT_FALSE(applyOverride(p, "pins=corners"));
  EXPECT_EQ(p.pins, PinMode::Corners);
  EXPECT_FALSE(applyOverride(p, "collision=off"));
  EXPECT_FALSE(p.collision);
  EXPECT_FALSE(applyOverride(p, "gravity=3.5"));
  EXPECT_FLOAT_EQ(p.gravity, 3.5f);
  for (const char* bad :
       {"nope=1", "cols=0", "cols=-3", "cols=1e3", "damping=1.01", "damping=x", "gravity=nan", "gravity=inf",
        "pins=middle", "wind=maybe", "substeps=33", "cols", "=4", "cols=99999999999", "contact_factor=-0.5",
        "contact_factor=nan", "contact_factor=1e30", "contact_settle=65", "contact_settle=-1"})
    EXPECT_TRUE(applyOverride(p, bad)) << bad;
  // Contact is off at 0 and on from 0.25 to 0.75 spacings: a radius under it (a denormal one,
  // which one path read as off and another as on) or past it (where a sheet at rest moves by
  // itself) is refused, and the message gives the range
  for (const char* bad : {"contact_factor=1e-38", "contact_factor=1e-33", "contact_factor=0.1", "contact_factor=1",
                          "contact_factor=2", "contact_factor=10"})
    EXPECT_TRUE(applyOverride(p, bad)) << bad;
  EXPECT_EQ(applyOverride(p, "contact_factor=1e-38").value_or(""),
            "contact_factor: 1e-38 is neither 0 (off) nor at least 0.25");
  EXPECT_EQ(applyOverride(p, "contact_factor=1").value_or(""), "contact_factor: 1 is out of range [0, 0.75]");
  for (const char* good : {"contact_factor=0", "contact_factor=0.25", "contact_factor=0.75"})
    EXPECT_FALSE(applyOverride(p, good)) << good;
  // The message says what is wrong: infinity is a number, but not a finite one
  EXPECT_EQ(applyOverride(p, "contact_factor=inf").value_or(""), "contact_factor: 'inf' is not finite");
  EXPECT_EQ(applyOverride(p, "gravity=nan").value_or(""), "gravity: 'nan' is not a number");
  // A closure just over 1 is printed with the digits that show it is (not as "1")
  EXPECT_EQ(checkClosure(1.0000001).value_or(""), "the closure 1.0000001 is out of range [0, 1] (0: open, 1: closed)");
  EXPECT_EQ(checkClosure(1.0 + 1e-9).value_or(""),
            "the closure 1.000000001 is out of range [0, 1] (0: open, 1: closed)");
}

TEST(Params, ValidateRejectsImpossibleSheets) {
  SimParams p = *presetParams("tender");
  p.cols = 16384;
  p.rows = 16384;
  EXPECT_TRUE(validate(p));
  p = *presetParams("tender");
  p.cell_size = 0.1f; // smaller than the collision radius
  EXPECT_TRUE(validate(p));
  p.collision = false;
  EXPECT_FALSE(validate(p));
}

TEST(Script, ParsesEveryEvent) {
  std::string err;
  auto s = parseScript("# demo\n0 grab particle 12\n0 grab ray 6 4 10 -0.5 -0.2 -1\n3 move 1 2.5 -3\n"
                       "4 release\n5 wind off\n5 pins toggle\n6 pause on\n7 reset  # again\n\n",
                       err);
  ASSERT_TRUE(s) << err;
  ASSERT_EQ(s->events.size(), 8u);
  EXPECT_EQ(s->events[0].kind, EventKind::GrabParticle);
  EXPECT_EQ(s->events[0].particle, 12u);
  EXPECT_EQ(s->events[1].kind, EventKind::GrabRay);
  EXPECT_FLOAT_EQ(s->events[1].b.z, -1.0f);
  EXPECT_EQ(s->events[2].a, glm::vec3(1.0f, 2.5f, -3.0f));
  EXPECT_EQ(s->events[5].toggle, Toggle::Flip);
  EXPECT_EQ(s->events[7].kind, EventKind::Reset);
  // Formatting and parsing round-trip.
  std::string text;
  for (auto& e : s->events) text += formatEvent(e) + "\n";
  auto again = parseScript(text, err);
  ASSERT_TRUE(again) << err;
  for (size_t i = 0; i < s->events.size(); ++i) EXPECT_EQ(formatEvent(again->events[i]), formatEvent(s->events[i]));
}

TEST(Script, RejectsMalformedLines) {
  for (const char* bad : {"x grab particle 1", "1 jump", "1 grab", "1 grab particle -1", "1 move 1 2", "1 move 1 2 nan",
                          "1 wind sideways", "1 reset now", "5 reset\n2 reset", "1 grab ray 0 0 0 0 0 0"}) {
    std::string err;
    EXPECT_FALSE(parseScript(bad, err)) << bad;
    EXPECT_NE(err.find("line "), std::string::npos) << err;
  }
  std::string err;
  EXPECT_FALSE(loadScript("/nonexistent/script.txt", err));
  EXPECT_NE(err.find("cannot read"), std::string::npos);
  EXPECT_FALSE(loadScript("/", err));
  EXPECT_NE(err.find("folder"), std::string::npos) << err;
}

TEST(Script, CoordinatesAndTicksStayInRange) {
  std::string err;
  // Beyond +-kMaxCoordinate, or beyond float, or not decimal: refused with the reason.
  for (const char* bad :
       {"1 move 1e30 0 0", "1 move 0 0 -1e39", "1 move 0 1000001 0", "0 grab ray 3e38 0 0 0 0 -1",
        "0 grab ray 0 0 0 1 inf 0", "99999999999999999999999 reset", "1000000000001 reset", "0x10 reset", "+5 reset"}) {
    EXPECT_FALSE(parseScript(bad, err)) << bad;
    EXPECT_NE(err.find("line 1"), std::string::npos) << err;
  }
  auto edge = parseScript("1000000000000 move 1000000 -1000000 999999.5", err);
  ASSERT_TRUE(edge) << err;
  EXPECT_EQ(edge->events[0].a, glm::vec3(1e6f, -1e6f, 999999.5f));
}

TEST(Script, AnEmptyFileHasNoEvents) {
  const std::string path = ::testing::TempDir() + "/tender_empty_script.txt";
  std::FILE* f = std::fopen(path.c_str(), "w");
  ASSERT_TRUE(f);
  std::fclose(f);
  std::string err;
  auto s = loadScriptFor(path, *presetParams("tender"), "cpu", err);
  ASSERT_TRUE(s) << err;
  EXPECT_TRUE(s->events.empty());
  std::remove(path.c_str());
}

TEST(Params, SheetCountsMatchTheBuiltSheet) {
  for (const char* name : {"tender", "crumple", "tender-low"})
    for (auto [cols, rows] : {std::pair{1u, 1u}, {2u, 1u}, {3u, 7u}, {32u, 48u}, {17u, 2u}}) {
      SimParams p = *presetParams(name);
      p.cols = cols;
      p.rows = rows;
      const SheetCounts c = sheetCounts(p);
      const SheetTopology t = buildSheet(p);
      EXPECT_EQ(c.particles, t.particleCount()) << name << " " << cols << "x" << rows;
      EXPECT_EQ(c.constraints, t.constraintCount()) << name << " " << cols << "x" << rows;
      EXPECT_EQ(c.triangles, t.triangleCount()) << name << " " << cols << "x" << rows;
      EXPECT_EQ(c.hash_buckets, t.hash_size) << name << " " << cols << "x" << rows;
    }
}

TEST(Params, MemoryEstimateRefusesWhatDoesNotFit) {
  SimParams p = *presetParams("tender");
  p.cols = p.rows = 1024;
  // About 1 KB per particle on the CPU, more on a GPU whose buffers live in host memory.
  const uint64_t cpu = estimateSheetBytes(p, "cpu"), gpu = estimateSheetBytes(p, "gpu");
  EXPECT_GT(cpu, 900ull << 20);
  EXPECT_GT(gpu, cpu);
  // 4096 x 4096 is within the particle limit and needs over 15 GiB.
  p.cols = p.rows = 4096;
  EXPECT_GT(estimateSheetBytes(p, "cpu"), 15ull << 30);
}
