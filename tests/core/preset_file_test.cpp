// Preset files: every built-in preset written as JSON reads back to the same parameters; files
// written by another program (stageAt) are committed whole or not at all.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <unistd.h>

#include "core/output.h"
#include "core/params.h"

using namespace tender;
namespace fs = std::filesystem;

namespace {

class PresetFile : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) / ("tender_preset_file_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const char* name, const std::string& text) const {
    const std::string p = (dir_ / name).string();
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
  static std::string read(const std::string& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
  }
  size_t files() const {
    size_t n = 0;
    for (auto& e : fs::directory_iterator(dir_)) n += e.is_regular_file();
    return n;
  }
  fs::path dir_;
};

TEST_F(PresetFile, EveryPresetRoundTrips) {
  for (const std::string& name : presetNames()) {
    const SimParams p = *presetParams(name);
    const std::string path = write("p.json", presetJson(p));
    SimParams loaded;
    ASSERT_EQ(loadPresetFile(path, loaded), std::nullopt) << name;
    EXPECT_EQ(loaded.preset, name);
    EXPECT_EQ(paramValues(loaded), paramValues(p)) << name;
    EXPECT_EQ(paramValues(p).size(), paramKeys().size());
  }
}

TEST_F(PresetFile, StartsFromItsPresetAndTakesSetSpellings) {
  const std::string path =
      write("p.json", R"({"preset": "crumple", "cols": "12", "gravity": 2.5, "collision": "off", "wind": true})");
  SimParams p;
  ASSERT_EQ(loadPresetFile(path, p), std::nullopt);
  SimParams want = *presetParams("crumple");
  for (const char* set : {"cols=12", "gravity=2.5", "collision=off", "wind=on"})
    ASSERT_EQ(applyOverride(want, set), std::nullopt);
  EXPECT_EQ(paramValues(p), paramValues(want));
}

TEST_F(PresetFile, BadFilesNameTheFile) {
  SimParams p;
  for (const char* text : {R"({"nope": 1})", R"({"cols": -1})", R"({"cols": [1]})", "{", "[]", R"({"preset": "x"})"}) {
    const std::string path = write("bad.json", text);
    auto err = loadPresetFile(path, p);
    ASSERT_TRUE(err) << text;
    EXPECT_EQ(err->rfind(path + ": ", 0), 0u) << *err;
    EXPECT_EQ(err->find('\n'), std::string::npos) << *err;
  }
  EXPECT_TRUE(loadPresetFile((dir_ / "missing.json").string(), p));
}

TEST_F(PresetFile, StageAtCommitsWholeOrNothing) {
  const std::string target = write("video.mp4", "earlier");
  {
    OutputSet out;
    ASSERT_EQ(out.add(target), std::nullopt);
    auto err = out.stageAt(target, [](const std::string& temp) -> std::optional<std::string> {
      std::ofstream(temp) << "half";
      return std::string("disk full");
    });
    ASSERT_TRUE(err);
    EXPECT_NE(err->find("disk full"), std::string::npos);
  }
  EXPECT_EQ(read(target), "earlier");
  EXPECT_EQ(files(), 1u);
  OutputSet out;
  ASSERT_EQ(out.add(target), std::nullopt);
  ASSERT_EQ(out.stageAt(target,
                        [&](const std::string& temp) -> std::optional<std::string> {
                          EXPECT_NE(temp, target);
                          std::ofstream(temp) << "whole";
                          return std::nullopt;
                        }),
            std::nullopt);
  EXPECT_EQ(read(target), "earlier");
  ASSERT_EQ(out.commit(), std::nullopt);
  EXPECT_EQ(read(target), "whole");
  EXPECT_EQ(files(), 1u);
}

} // namespace
