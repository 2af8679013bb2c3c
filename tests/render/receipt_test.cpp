// The receipt: its texts (a total that is the sum of the items) and where the ink lands.
#include <gtest/gtest.h>

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
  ASSERT_EQ(img.width, 512u);
  ASSERT_EQ(img.height, 768u);
  ASSERT_EQ(img.rgba.size(), size_t(512) * 768 * 4);
  // Header, 2 address lines, 9 items x 2 columns, total x 2, 2 thanks, barcode digits; dividers; barcode.
  ASSERT_GE(img.lines.size(), 20u);
  for (auto& l : img.lines) {
    EXPECT_GT(inkIn(img, l.x0, l.y0, l.x1, l.y1), 10) << "no ink on '" << l.text << "'";
    EXPECT_GE(l.x0, 0);
    EXPECT_LE(l.x1, 512);
    EXPECT_GE(l.y0, 0);
    EXPECT_LE(l.y1, 768);
  }
  // The margins stay blank paper.
  EXPECT_EQ(inkIn(img, 0, 0, 30, 768), 0);
  EXPECT_EQ(inkIn(img, 482, 0, 512, 768), 0);
  EXPECT_EQ(inkIn(img, 0, 0, 512, 20), 0);
  // The header is the first line, centred, near the top.
  const PrintedLine& h = img.lines.front();
  EXPECT_EQ(h.text, "PHYSICS DINER");
  EXPECT_NEAR((h.x0 + h.x1) / 2, 256, 4);
  EXPECT_LT(h.y1, 120);
  // The barcode is solid ink over much of its box.
  for (auto& l : img.lines) {
    if (l.text == "|||") {
      EXPECT_GT(inkIn(img, l.x0, l.y0, l.x1, l.y1), (l.x1 - l.x0) * (l.y1 - l.y0) / 4);
    }
  }
}

TEST(Receipt, MissingFontIsOneClearError) {
  try {
    rasterizeReceipt(receiptText("tender"), "/nonexistent/DejaVuSansMono.ttf");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    std::string m = e.what();
    EXPECT_NE(m.find("/nonexistent/DejaVuSansMono.ttf"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
}
