// Output files: checked before a run, written whole or not at all, never two outputs in one file.
#include <gtest/gtest.h>

#include <cerrno>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <unistd.h>

#include "common/sim_helpers.h"
#include "core/output.h"
#include "core/simulation.h"

using namespace tender;
using namespace tender::test;
namespace fs = std::filesystem;

namespace {

class Output : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) / ("tender_output_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const char* name) const { return (dir_ / name).string(); }
  static std::string read(const std::string& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
  }
  // Files in the folder other than the given one (temporary files left behind).
  size_t strayFiles(const std::string& keep) const {
    size_t n = 0;
    for (auto& e : fs::directory_iterator(dir_)) n += e.path().string() != keep;
    return n;
  }
  fs::path dir_;
};

} // namespace

TEST_F(Output, WritesTheWholeFileAndNothingElse) {
  const std::string p = path("a.json");
  EXPECT_FALSE(writeFileAtomically(p, "{\"x\": 1}\n"));
  EXPECT_EQ(read(p), "{\"x\": 1}\n");
  EXPECT_EQ(strayFiles(p), 0u);
}

TEST_F(Output, AFailedWriteKeepsTheEarlierFile) {
  const std::string p = path("keep.ply");
  ASSERT_FALSE(writeFileAtomically(p, "good"));
  auto err = writeFileAtomically(p, [](std::FILE* f) {
    std::fputs("half a fil", f);
    errno = ENOSPC;
    return false;
  });
  ASSERT_TRUE(err);
  EXPECT_NE(err->find("keep.ply"), std::string::npos) << *err;
  EXPECT_NE(err->find("No space left"), std::string::npos) << *err;
  EXPECT_EQ(read(p), "good");
  EXPECT_EQ(strayFiles(p), 0u);
}

TEST_F(Output, ADeviceIsWrittenInPlaceAndItsErrorsCount) {
  auto err = writeFileAtomically("/dev/full", std::string(100000, 'x'));
  ASSERT_TRUE(err);
  EXPECT_NE(err->find("/dev/full"), std::string::npos) << *err;
  EXPECT_FALSE(writeFileAtomically("/dev/null", "nothing"));
}

TEST_F(Output, PathsAreCheckedBeforeTheRun) {
  OutputSet set;
  EXPECT_TRUE(set.add("/nonexistent/folder/x.ply"));
  EXPECT_TRUE(set.add(dir_.string()));          // a folder
  EXPECT_TRUE(set.add(path("missing/x.json"))); // no such folder
  EXPECT_FALSE(set.add(""));                    // no output
  EXPECT_FALSE(set.add(path("s.json")));
  EXPECT_TRUE(set.add(path("s.json")));                   // the same file twice
  EXPECT_TRUE(set.add((dir_ / "." / "s.json").string())); // the same file by another name
  EXPECT_FALSE(set.add(path("s.ply")));
}

TEST_F(Output, NothingIsRenamedUntilTheWholeSetIsWritten) {
  const std::string a = path("a.json"), b = path("b.ply");
  {
    OutputSet set;
    ASSERT_FALSE(set.add(a));
    ASSERT_FALSE(set.add(b));
    ASSERT_FALSE(set.stage(a, "stats"));
    ASSERT_TRUE(set.stage(b, [](std::FILE*) { return errno = EIO, false; }));
    // No commit: the set is dropped and its temporary files with it.
  }
  EXPECT_FALSE(fs::exists(a));
  EXPECT_FALSE(fs::exists(b));
  EXPECT_EQ(strayFiles(""), 0u);
  OutputSet set;
  ASSERT_FALSE(set.add(a));
  ASSERT_FALSE(set.stage(a, "stats"));
  EXPECT_FALSE(fs::exists(a));
  ASSERT_FALSE(set.commit());
  EXPECT_EQ(read(a), "stats");
}

TEST(Simulation, GrabTargetsStayWithinTheCoordinateLimit) {
  class Still final : public Solver { // a solver that holds the sheet at rest
  public:
    std::string name() const override { return "still"; }
    void upload(const SheetTopology& t) override { topo_ = &t; }
    void tick(const shaderio::SimUniforms&) override {}
    void beginReset() override {}
    void computeNormals() override {}
    shaderio::PickResult pick(glm::vec3, glm::vec3, float) override {
      shaderio::PickResult none{};
      none.index = SIM_NONE;
      return none;
    }
    glm::vec3 particlePosition(uint32_t i) override { return glm::vec3(topo_->rest_pos[i]); }
    void readback(SimState&) override {}
    void stopNextTickAfter(uint32_t) override {}
    void readDeltas(std::vector<glm::vec4>&) override {}

  private:
    const SheetTopology* topo_ = nullptr;
  } still;
  SimParams p = clothWithContact();
  Simulation sim(p, still);
  sim.grabParticle(5);
  sim.moveGrab(glm::vec3(1e30f, -INFINITY, NAN));
  EXPECT_EQ(sim.grabTarget(), glm::vec3(kMaxCoordinate, -kMaxCoordinate, 0.0f));
  const shaderio::SimUniforms u = sim.makeUniforms();
  for (uint32_t s = 0; s < p.substeps; ++s)
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(std::isfinite(u.grab_target[s][k]) && std::isfinite(u.grab_prev[s][k]));
}
