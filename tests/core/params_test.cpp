#include <gtest/gtest.h>

#include "core/params.h"
#include "core/script.h"

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
  EXPECT_FALSE(presetParams("paper"));
  for (auto& name : presetNames()) EXPECT_FALSE(validate(*presetParams(name))) << name;
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
  for (const char* bad : {"nope=1", "cols=0", "cols=-3", "cols=1e3", "damping=1.01", "damping=x", "gravity=nan",
                          "gravity=inf", "pins=middle", "wind=maybe", "substeps=33", "cols", "=4", "cols=99999999999"})
    EXPECT_TRUE(applyOverride(p, bad)) << bad;
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
}
