// Golden images: small renders of presets on the CPU backend (deterministic) through the Vulkan
// renderer on lavapipe, compared with committed PNGs.
//
// Tolerance: a pixel differs when a channel is off by more than 24 levels; at most 0.5% of the
// pixels may differ and the mean absolute channel error must stay below 1.5 levels (rasteriser
// and driver rounding, not a changed picture). The goldens are lavapipe's pictures: on another
// device, whose texture filtering (level of detail, anisotropy) Vulkan leaves to the driver, a
// pixel differs only when no golden pixel within one pixel of it is within the 24 levels (the
// edges of the printed text move by up to a pixel: 0.6-0.8% of the pixels on an NVIDIA H200,
// mean error 0.8-0.9 levels); the mean error stays the whole picture's.
// On failure the actual picture and a diff are written next to the test binary's working
// directory as golden_<name>_actual.png and golden_<name>_diff.png.
// Regenerate the goldens after an intended change with
//   TENDER_UPDATE_GOLDEN=1 VK_DRIVER_FILES=/usr/share/vulkan/icd.d/lvp_icd.x86_64.json
//     ./tests/tender_render_tests --gtest_filter='Golden.*'
// and look at the new PNGs in tests/render/data before committing them.
// The goldens are read from (and written to) $TENDER_TEST_DATA when it is set, so that a copy of
// the test binary elsewhere (tools/gpu-bundle) finds its data; otherwise from tests/render/data.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "backend/headless.h"
#include "core/params.h"
#include "gpu/context.h"

using namespace tender;

namespace {

constexpr int kChannelTolerance = 24;
constexpr double kMaxDifferentFraction = 0.005;
constexpr double kMaxMeanError = 1.5;

render::HeadlessResult renderScene(const SimParams& params, uint64_t ticks, const std::string& script_text,
                                   const std::string& backend = "cpu") {
  gpu::preferLavapipeForTests();
  render::HeadlessOptions o;
  o.params = params;
  o.backend = backend;
  o.validation = true;
  o.ticks = ticks;
  o.width = 320;
  o.height = 240;
  if (!script_text.empty()) {
    std::string error;
    auto s = parseScript(script_text, error);
    EXPECT_TRUE(s.has_value()) << error;
    if (s) o.script = *s;
  }
  return render::renderHeadless(o);
}

render::HeadlessResult renderPreset(const std::string& preset, uint64_t ticks, const std::string& script_text,
                                    const std::string& backend = "cpu") {
  return renderScene(*presetParams(preset), ticks, script_text, backend);
}

/// The folder of the golden PNGs: $TENDER_TEST_DATA, or the source tree's folder built in.
std::string testDataDir() {
  const char* dir = std::getenv("TENDER_TEST_DATA");
  return dir && *dir ? dir : TENDER_TEST_DATA;
}

/// True when pixel p of `actual` is within the tolerance of pixel q of `golden` in every channel.
bool within(const render::Picture& actual, size_t p, const render::Picture& golden, size_t q) {
  for (int c = 0; c < 3; ++c)
    if (std::abs(int(actual.rgba[p * 4 + c]) - int(golden.rgba[q * 4 + c])) > kChannelTolerance) return false;
  return true;
}

void compareWithGolden(const std::string& name, const render::HeadlessResult& result) {
  const render::Picture& actual = result.picture;
  const bool lavapipe = result.device.rfind("llvmpipe", 0) == 0;
  const std::string golden_path = testDataDir() + "/golden_" + name + ".png";
  if (const char* u = std::getenv("TENDER_UPDATE_GOLDEN"); u && std::string(u) == "1") {
    ASSERT_FALSE(render::writePng(golden_path, actual));
    GTEST_SKIP() << "wrote " << golden_path;
  }
  render::Picture golden = render::readPng(golden_path);
  ASSERT_FALSE(golden.rgba.empty()) << "missing golden " << golden_path << " (TENDER_UPDATE_GOLDEN=1 writes it)";
  ASSERT_EQ(golden.width, actual.width);
  ASSERT_EQ(golden.height, actual.height);
  render::Picture diff = actual;
  size_t different = 0;
  double total = 0.0;
  const size_t pixels = size_t(actual.width) * actual.height;
  for (size_t p = 0; p < pixels; ++p) {
    for (int c = 0; c < 3; ++c) total += std::abs(int(actual.rgba[p * 4 + c]) - int(golden.rgba[p * 4 + c]));
    bool close = within(actual, p, golden, p);
    const int x = int(p % actual.width), y = int(p / actual.width);
    for (int dy = -1; dy <= 1 && !close && !lavapipe; ++dy)
      for (int dx = -1; dx <= 1 && !close; ++dx) {
        const int nx = x + dx, ny = y + dy;
        if (nx >= 0 && ny >= 0 && nx < int(actual.width) && ny < int(actual.height))
          close = within(actual, p, golden, size_t(ny) * actual.width + size_t(nx));
      }
    const bool differs = !close;
    different += differs;
    // Diff image: differences in red over a faded copy of the golden.
    uint8_t g = uint8_t(golden.rgba[p * 4 + 1] / 3 + 170);
    diff.rgba[p * 4 + 0] = differs ? 255 : g;
    diff.rgba[p * 4 + 1] = differs ? 0 : g;
    diff.rgba[p * 4 + 2] = differs ? 0 : g;
    diff.rgba[p * 4 + 3] = 255;
  }
  const double fraction = double(different) / double(pixels);
  const double mean = total / double(pixels * 3);
  const bool ok = fraction <= kMaxDifferentFraction && mean <= kMaxMeanError;
  if (!ok) {
    (void)render::writePng("golden_" + name + "_actual.png", actual);
    (void)render::writePng("golden_" + name + "_diff.png", diff);
  }
  EXPECT_TRUE(ok) << name << " (" << result.device << "): " << different << " pixels (" << fraction * 100.0
                  << "%) differ, mean error " << mean << "; wrote "
                  << std::filesystem::absolute("golden_" + name + "_actual.png") << " and _diff.png";
}

// Printed ink in the picture: pixels much darker than the background, the ground and the shadow.
size_t inkPixels(const render::Picture& p) {
  size_t n = 0;
  for (size_t i = 0; i < size_t(p.width) * p.height; ++i)
    n += p.rgba[i * 4] < 100 && p.rgba[i * 4 + 1] < 100 && p.rgba[i * 4 + 2] < 100;
  return n;
}

/// True when a render failed only because this machine has no Vulkan device (a skip outside CI).
bool noDevice(const render::HeadlessResult& r) {
  const char* ci = std::getenv("CI");
  const bool in_ci = ci && std::string(ci) == "true";
  return !in_ci && (r.error.find("no Vulkan device") != std::string::npos ||
                    r.error.find("no Vulkan driver") != std::string::npos);
}

} // namespace

// A missing device skips (outside CI); any other error (a missing validation layer or font, a
// Vulkan error) fails.
#define SKIP_OR_FAIL_ON_ERROR(r)                                                                                       \
  do {                                                                                                                 \
    if (!(r).error.empty() && noDevice(r)) GTEST_SKIP() << (r).error;                                                  \
    ASSERT_TRUE((r).error.empty()) << (r).error;                                                                       \
  } while (0)

TEST(Golden, TenderPresetHangingFromItsPins) {
  auto r = renderPreset("tender", 60, "");
  SKIP_OR_FAIL_ON_ERROR(r);
  EXPECT_EQ(r.validation_messages, 0u);
  ASSERT_EQ(r.picture.width, 320u);
  EXPECT_GT(inkPixels(r.picture), 150u); // the receipt's text and barcode
  compareWithGolden("tender_60", r);
}

TEST(Golden, TornSheetShowsTheGap) {
  // Pull the bottom edge down hard: the sheet tears at its pins and the compacted triangles leave
  // gaps. The seeds' cloth, SimParams' defaults: no contact (a CPU device builds contact's kernels
  // in seconds)
  auto r = renderScene(SimParams{}, 40,
                       "0 wind off\n0 grab particle 1520\n1 move 0 -4.5 0\n5 move 0 -6 0\n10 move 0 -8 0\n"
                       "15 move 0 -10 0\n",
                       "cpu");
  SKIP_OR_FAIL_ON_ERROR(r);
  EXPECT_EQ(r.validation_messages, 0u);
  compareWithGolden("tender_torn", r);
}

TEST(Golden, CrumplePresetPrintsItsReceipt) {
  auto r = renderPreset("crumple", 30, "");
  SKIP_OR_FAIL_ON_ERROR(r);
  EXPECT_EQ(r.validation_messages, 0u);
  compareWithGolden("crumple_30", r);
}

TEST(Golden, AHandCrumpledReceiptShowsItsCreases) {
  // The hand closes around the middle of the crumple sheet hanging from its corners: the creases
  // show as sharp lines between flat facets (cornerNormal), not as smooth shading.
  std::string text = "0 grab particle 1220\n1 move 0 0.5 1\n";
  for (int t = 1; t <= 30; ++t) text += std::to_string(t) + " squeeze " + std::to_string(t / 30.0) + "\n";
  auto r = renderPreset("crumple", 90, text);
  SKIP_OR_FAIL_ON_ERROR(r);
  EXPECT_EQ(r.validation_messages, 0u);
  compareWithGolden("crumple_hand", r);
}

// The GPU backend: the renderer binds the solver's own buffers and draws the live triangles with
// the indirect arguments the tear compaction writes; the solvers agree, so the pictures do too (the
// preset as it ships, contact on; its hanging sheet keeps the bits it has without contact).
TEST(Golden, GpuSolverBuffersDrawTheSamePicture) {
  auto r = renderPreset("tender", 60, "", "gpu");
  SKIP_OR_FAIL_ON_ERROR(r);
  EXPECT_EQ(r.validation_messages, 0u);
  if (std::getenv("TENDER_UPDATE_GOLDEN")) GTEST_SKIP() << "the CPU render is the golden";
  compareWithGolden("tender_60", r);
}

TEST(Golden, GpuSolverTornSheet) {
  auto r = renderScene(SimParams{}, 40,
                       "0 wind off\n0 grab particle 1520\n1 move 0 -4.5 0\n5 move 0 -6 0\n10 move 0 -8 0\n"
                       "15 move 0 -10 0\n",
                       "gpu");
  SKIP_OR_FAIL_ON_ERROR(r);
  EXPECT_EQ(r.validation_messages, 0u);
  if (std::getenv("TENDER_UPDATE_GOLDEN")) GTEST_SKIP() << "the CPU render is the golden";
  compareWithGolden("tender_torn", r);
}
