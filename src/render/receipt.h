#pragma once
/// The receipt printed on the paper: its text per preset, and its rasterisation with FreeType
/// into an RGBA image of any width, 2:3 (dark ink on off-white), laid out the same at every size.
#include <cstdint>
#include <string>
#include <vector>

namespace tender::render {

/// Size of the renderer's receipt texture in pixels: at the closest zoom (radius 3, 50 degrees of
/// view over 720 pixels: 257 pixels per unit) a texel of a 5.6 to 5.9 units wide sheet covers at
/// most one pixel (1536 / 5.85 = 263 texels per unit).
constexpr uint32_t kReceiptWidth = 1536;
constexpr uint32_t kReceiptHeight = kReceiptWidth * 3 / 2;
/// The width the receipt's layout is written for: positions and font sizes are in 1/512 of the
/// image's width, so at this width they are pixels.
constexpr uint32_t kReceiptLayoutWidth = 512;
/// The monospace font the receipt is printed with (Debian's fonts-dejavu-core).
constexpr const char* kReceiptFont = "/usr/share/fonts/truetype/dejavu/DejaVuSansMono.ttf";
/// The receipt font: $TENDER_FONT when set (a self-contained bundle ships its own), else kReceiptFont.
std::string receiptFontPath();

/// One priced line of the receipt.
struct ReceiptItem {
  std::string name;
  uint32_t cents = 0; ///< price; 0 with `value` set prints the value instead of a price
  std::string value;  ///< non-price value (the crumple receipt's specification lines)
};

/// What a receipt says.
struct ReceiptText {
  std::string header;               ///< "PHYSICS DINER"
  std::vector<std::string> address; ///< lines under the header
  std::vector<ReceiptItem> items;   ///< nine menu items (or specification lines)
  std::string total_label;          ///< "TOTAL"
  std::string total_value;          ///< the sum of the items, formatted
  std::vector<std::string> thanks;  ///< thank-you lines
  std::string barcode;              ///< digits printed under the barcode
};

/// The receipt of a preset: the diner receipt, or the crumple preset's simulation receipt.
ReceiptText receiptText(const std::string& preset);
/// Price in cents formatted as "12.34".
std::string formatPrice(uint32_t cents);

/// Where one printed line landed (pixel rectangle, for tests).
struct PrintedLine {
  std::string text;
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

/// An RGBA8 image of the receipt, rows top to bottom.
struct ReceiptImage {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgba;
  std::vector<PrintedLine> lines; ///< every text line, divider and the barcode
};

/// Rasterises a receipt `width` pixels wide and 1.5 times as high (width at least 64); throws
/// std::runtime_error with one clear line when the font is missing.
ReceiptImage rasterizeReceipt(const ReceiptText& text, uint32_t width = kReceiptWidth,
                              const std::string& font_path = receiptFontPath());

} // namespace tender::render
