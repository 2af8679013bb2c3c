// The receipt: its texts (a total that is the sum of the items) and where the ink lands.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "render/receipt.h"

using namespace tender::render;

namespace {

// Cents of a "12.34" price.
uint32_t parseCents(const std::string& s) {
  size_t dot = s.find('.');
  return uint32_t(std::stoul(s.substr(0, dot)) * 100 + std::stoul(s.substr(dot + 1)));
}

// Ink pixels (clearly darker than the paper) in a rectangle.
int inkIn(const ReceiptImage& img, int x0, int y0, int x1, int y1) {
  int n = 0;
  for (int y = std::max(y0, 0); y < std::min(y1, int(img.height)); ++y)
    for (int x = std::max(x0, 0); x < std::min(x1, int(img.width)); ++x)
      if (img.rgba[(size_t(y) * img.width + size_t(x)) * 4] < 128) ++n;
  return n;
}

} // namespace

TEST(Receipt, DinerReceiptHasNineItemsAndTheirSum) {
  ReceiptText t = receiptText("tender");
  EXPECT_EQ(t.header, "PHYSICS DINER");
  ASSERT_EQ(t.items.size(), 9u);
  uint32_t sum = 0;
  for (auto& it : t.items) {
    EXPECT_GT(it.cents, 0u) << it.name;
    sum += it.cents;
  }
  EXPECT_EQ(parseCents(t.total_value), sum);
  EXPECT_EQ(t.total_value, formatPrice(sum));
  EXPECT_FALSE(t.address.empty());
  EXPECT_FALSE(t.thanks.empty());
  EXPECT_FALSE(t.barcode.empty());
}

TEST(Receipt, FormatsPrices) {
  EXPECT_EQ(formatPrice(0), "0.00");
  EXPECT_EQ(formatPrice(5), "0.05");
  EXPECT_EQ(formatPrice(1250), "12.50");
}

TEST(Receipt, CrumplePrintsTheSimulationReceipt) {
  ReceiptText t = receiptText("crumple");
  EXPECT_NE(t.header, "PHYSICS DINER");
  bool model = false, tokens = false;
  for (auto& it : t.items) {
    model |= it.name == "Model" && it.value == "DeepSeek-V3.2";
    tokens |= it.name == "Tokens" && it.value == "2400 particles";
  }
  EXPECT_TRUE(model);
  EXPECT_TRUE(tokens);
  EXPECT_EQ(receiptText("crumple-low").header, t.header);
  EXPECT_EQ(receiptText("tender-low").header, "PHYSICS DINER");
}

TEST(Receipt, InkLandsOnEveryLineAndNowhereElse) {
  ReceiptImage img = rasterizeReceipt(receiptText("tender"));
  ASSERT_EQ(img.width, kReceiptWidth);
  ASSERT_EQ(img.height, kReceiptHeight);
  ASSERT_EQ(img.height * 2, img.width * 3);
  ASSERT_EQ(img.rgba.size(), size_t(img.width) * img.height * 4);
  const int w = int(img.width), h = int(img.height), unit = w / int(kReceiptLayoutWidth);
  // Header, 2 address lines, 9 items x 2 columns, total x 2, 2 thanks, barcode digits; dividers; barcode.
  ASSERT_GE(img.lines.size(), 20u);
  for (auto& l : img.lines) {
    EXPECT_GT(inkIn(img, l.x0, l.y0, l.x1, l.y1), 10 * unit * unit) << "no ink on '" << l.text << "'";
    EXPECT_GE(l.x0, 0);
    EXPECT_LE(l.x1, w);
    EXPECT_GE(l.y0, 0);
    EXPECT_LE(l.y1, h);
  }
  // The margins (30 of the layout's 512 units) stay blank paper.
  EXPECT_EQ(inkIn(img, 0, 0, 30 * unit, h), 0);
  EXPECT_EQ(inkIn(img, w - 30 * unit, 0, w, h), 0);
  EXPECT_EQ(inkIn(img, 0, 0, w, 20 * unit), 0);
  // The header is the first line, centred, near the top.
  const PrintedLine& hl = img.lines.front();
  EXPECT_EQ(hl.text, "PHYSICS DINER");
  EXPECT_NEAR((hl.x0 + hl.x1) / 2, w / 2, 4 * unit);
  EXPECT_LT(hl.y1, 120 * unit);
  // The barcode is solid ink over much of its box.
  for (auto& l : img.lines) {
    if (l.text == "|||") {
      EXPECT_GT(inkIn(img, l.x0, l.y0, l.x1, l.y1), (l.x1 - l.x0) * (l.y1 - l.y0) / 4);
    }
  }
}

namespace {

// The box around all the ink of an image: x0, y0, x1, y1 (exclusive).
std::array<int, 4> inkBox(const ReceiptImage& img) {
  std::array<int, 4> b = {int(img.width), int(img.height), 0, 0};
  for (int y = 0; y < int(img.height); ++y)
    for (int x = 0; x < int(img.width); ++x)
      if (img.rgba[(size_t(y) * img.width + size_t(x)) * 4] < 128)
        b = {std::min(b[0], x), std::min(b[1], y), std::max(b[2], x + 1), std::max(b[3], y + 1)};
  return b;
}

double inkFraction(const ReceiptImage& img) {
  return double(inkIn(img, 0, 0, int(img.width), int(img.height))) / (double(img.width) * img.height);
}

} // namespace

TEST(Receipt, LayoutScalesWithTheWidth) {
  for (const char* preset : {"tender", "crumple"}) {
    const ReceiptImage small = rasterizeReceipt(receiptText(preset), 512);
    const ReceiptImage large = rasterizeReceipt(receiptText(preset), 1024);
    ASSERT_EQ(large.width, 1024u);
    ASSERT_EQ(large.height, 1536u);
    // The ink's box twice as large within a few pixels
    const auto a = inkBox(small), b = inkBox(large);
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(b[size_t(k)], 2 * a[size_t(k)], 4) << preset << " ink box side " << k;
    // Every printed line at twice the height, its anchor (left, right or centre) at twice the
    // distance, and its length twice as long within 6% (hinting rounds each size's monospace
    // advance to whole pixels on its own)
    ASSERT_EQ(small.lines.size(), large.lines.size());
    for (size_t i = 0; i < small.lines.size(); ++i) {
      const PrintedLine &s = small.lines[i], &l = large.lines[i];
      EXPECT_EQ(s.text, l.text);
      EXPECT_NEAR(l.y0, 2 * s.y0, 3) << s.text;
      EXPECT_NEAR(l.y1, 2 * s.y1, 3) << s.text;
      const bool anchored = std::abs(l.x0 - 2 * s.x0) <= 2 || std::abs(l.x1 - 2 * s.x1) <= 2 ||
                            std::abs((l.x0 + l.x1) - 2 * (s.x0 + s.x1)) <= 4;
      EXPECT_TRUE(anchored) << s.text << ": " << s.x0 << ".." << s.x1 << " at 512, " << l.x0 << ".." << l.x1;
      const int length = 2 * (s.x1 - s.x0);
      EXPECT_NEAR(l.x1 - l.x0, length, 0.06 * length + 2) << s.text;
    }
    // The same share of the paper is ink: the text is as bold and as legible at both sizes
    EXPECT_NEAR(inkFraction(large), inkFraction(small), 0.1 * inkFraction(small)) << preset;
  }
}

TEST(Receipt, TheRenderersTextureIsSharpAtTheClosestZoom) {
  // At the camera's closest zoom (radius 3, 50 degrees of view) a 1280 x 720 window shows
  // 720 / (2 * 3 * tan 25 deg) = 257 pixels per unit; the widest sheet (crumple, 39 x 0.15 units)
  // gets at least as many texels per unit.
  const double pixels_per_unit = 720.0 / (2.0 * 3.0 * std::tan(25.0 * 3.14159265358979 / 180.0));
  EXPECT_GE(double(kReceiptWidth) / (39 * 0.15), pixels_per_unit);
  EXPECT_GE(double(kReceiptHeight) / (59 * 0.15), pixels_per_unit);
}

TEST(Receipt, MissingFontIsOneClearError) {
  try {
    rasterizeReceipt(receiptText("tender"), 512, "/nonexistent/DejaVuSansMono.ttf");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    std::string m = e.what();
    EXPECT_NE(m.find("/nonexistent/DejaVuSansMono.ttf"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
}
