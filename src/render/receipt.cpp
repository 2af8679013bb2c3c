#include "receipt.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include <ft2build.h>
#include FT_FREETYPE_H

namespace tender::render {
namespace {

// Paper and ink colours (sRGB).
constexpr uint8_t kPaper[3] = {0xf8, 0xf7, 0xf2};
constexpr uint8_t kInk[3] = {0x2a, 0x2a, 0x2a};
// Left and right margin (layout units: 1/512 of the width).
constexpr int kMargin = 36;

// Owns a FreeType library and one face.
class Font {
public:
  explicit Font(const std::string& path) {
    if (FT_Init_FreeType(&lib_)) throw std::runtime_error("cannot initialise FreeType");
    if (FT_New_Face(lib_, path.c_str(), 0, &face_)) {
      FT_Done_FreeType(lib_);
      throw std::runtime_error("cannot load the receipt font '" + path + "' (install fonts-dejavu-core)");
    }
  }
  ~Font() {
    FT_Done_Face(face_);
    FT_Done_FreeType(lib_);
  }
  Font(const Font&) = delete;
  Font& operator=(const Font&) = delete;

  void setSize(int px) { FT_Set_Pixel_Sizes(face_, 0, FT_UInt(px)); }
  // Advance of one character (monospace) in pixels.
  int advance() {
    FT_Load_Char(face_, 'M', FT_LOAD_DEFAULT);
    return int(face_->glyph->advance.x >> 6);
  }
  FT_Face face() { return face_; }

private:
  FT_Library lib_ = nullptr;
  FT_Face face_ = nullptr;
};

// Decodes one UTF-8 code point and advances i.
uint32_t nextCodepoint(const std::string& s, size_t& i) {
  auto c = uint8_t(s[i++]);
  if (c < 0x80) return c;
  int extra = c >= 0xf0 ? 3 : c >= 0xe0 ? 2 : 1;
  uint32_t cp = c & (0x3fu >> extra);
  for (int k = 0; k < extra && i < s.size(); ++k) cp = (cp << 6) | (uint8_t(s[i++]) & 0x3fu);
  return cp;
}

size_t codepointCount(const std::string& s) {
  size_t n = 0;
  for (size_t i = 0; i < s.size(); ++n) nextCodepoint(s, i);
  return n;
}

// Prints on the image at a layout written for kReceiptLayoutWidth: every position, size and
// thickness the methods take is in layout units and scaled to the image's pixels.
class Printer {
public:
  Printer(ReceiptImage& img, Font& font)
      : img_(img), font_(font), scale_(double(img.width) / double(kReceiptLayoutWidth)) {}

  // Layout units to pixels.
  int px(double units) const { return int(std::lround(units * scale_)); }

  // Blends ink over the paper at (x, y) with coverage a (0..255).
  void ink(int x, int y, uint32_t a) {
    if (x < 0 || y < 0 || x >= int(img_.width) || y >= int(img_.height) || a == 0) return;
    uint8_t* p = &img_.rgba[(size_t(y) * img_.width + size_t(x)) * 4];
    for (int c = 0; c < 3; ++c) p[c] = uint8_t((p[c] * (255 - a) + kInk[c] * a + 127) / 255);
  }

  // Prints text of font size `size` with its baseline at y; x < 0 centres it.
  void text(const std::string& s, int size, int x, int y, bool bold = false) {
    printAt(s, px(size), x < 0 ? -1 : px(x), px(y), bold);
  }

  // Prints `left` at the left margin and `right` flush with the right margin.
  void columns(const std::string& left, const std::string& right, int size, int y, bool bold = false) {
    text(left, size, kMargin, y, bold);
    const int right_edge = int(img_.width) - px(kMargin);
    printAt(right, px(size), right_edge - textWidth(right, px(size)), px(y), bold);
  }

  // A dashed rule two units thick with its top at y.
  void dashes(int y) {
    const int x0 = px(kMargin), x1 = int(img_.width) - x0, top = px(y), bottom = px(y + 2);
    for (int x = x0; x < x1; ++x)
      if (std::fmod(double(x - x0) / scale_, 12.0) < 7.0) // 7 units of dash, 5 of gap
        for (int yy = top; yy < bottom; ++yy) ink(x, yy, 255);
    img_.lines.push_back({"----", x0, top, x1, bottom});
  }

  // A faux barcode between y0 and y1: bar widths from the digits, framed by guard bars.
  void barcode(const std::string& digits, int y0_units, int y1_units) {
    const int y0 = px(y0_units), y1 = px(y1_units);
    std::vector<int> widths = {1, 1, 1, 1}; // start guard: bar, space, bar, space
    for (char ch : digits) {
      int d = ch - '0';
      int pattern[4] = {1 + d % 3, 1 + (d + 1) % 2, 1 + (d * 7) % 4, 1 + (d + 2) % 3};
      widths.insert(widths.end(), pattern, pattern + 4);
    }
    widths.insert(widths.end(), {1, 1, 1});
    int total = 0;
    for (int w : widths) total += w;
    // Whole layout units per module, then every bar edge scaled to pixels
    const int module = std::max(1, (int(kReceiptLayoutWidth) - 2 * kMargin - 40) / total);
    const int x_start = (int(img_.width) - px(total * module)) / 2;
    int units = 0;
    for (size_t k = 0; k < widths.size(); ++k) {
      const int x0 = x_start + px(units), x1 = x_start + px(units + widths[k] * module);
      if (k % 2 == 0)
        for (int x = x0; x < x1; ++x)
          for (int y = y0; y < y1; ++y) ink(x, y, 255);
      units += widths[k] * module;
    }
    img_.lines.push_back({"|||", x_start, y0, x_start + px(units), y1});
  }

private:
  // Width of a line of text at this pixel size (monospace).
  int textWidth(const std::string& s, int size) {
    font_.setSize(size);
    return int(codepointCount(s)) * font_.advance();
  }

  // Prints text at pixel size `size` with its baseline at pixel row `baseline`; x < 0 centres it.
  void printAt(const std::string& s, int size, int x, int baseline, bool bold) {
    const int w = textWidth(s, size);
    if (x < 0) x = (int(img_.width) - w) / 2;
    FT_Face f = font_.face();
    // Bold: printed again shifted right by up to one layout unit
    const int shifts = bold ? std::max(1, px(1)) : 0;
    int pen = x;
    for (size_t i = 0; i < s.size();) {
      uint32_t cp = nextCodepoint(s, i);
      if (FT_Load_Char(f, cp, FT_LOAD_RENDER)) continue;
      const FT_Bitmap& bm = f->glyph->bitmap;
      for (int shift = 0; shift <= shifts; ++shift)
        for (unsigned r = 0; r < bm.rows; ++r)
          for (unsigned c = 0; c < bm.width; ++c)
            ink(pen + f->glyph->bitmap_left + int(c) + shift, baseline - f->glyph->bitmap_top + int(r),
                bm.buffer[r * unsigned(bm.pitch) + c]);
      pen += int(f->glyph->advance.x >> 6);
    }
    img_.lines.push_back({s, x, baseline - size * 3 / 4, x + w, baseline + size / 4});
  }

  ReceiptImage& img_;
  Font& font_;
  double scale_; // pixels per layout unit
};

} // namespace

std::string formatPrice(uint32_t cents) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%u.%02u", cents / 100, cents % 100);
  return buf;
}

ReceiptText receiptText(const std::string& preset) {
  ReceiptText t;
  if (preset.rfind("crumple", 0) == 0) {
    // The receipt of the crumple specification: a run of a one-shot physics simulation.
    t.header = "ONE-SHOT PHYSICS";
    t.address = {"Simulation Receipt", "Receipt Paper Physics", "2026-04-06  #0042"};
    t.items = {{"Model", 0, "DeepSeek-V3.2"}, {"Tokens", 0, "2400 particles"}, {"Grid", 0, "40 x 60"},
               {"Integration", 0, "Verlet"},  {"Timestep", 0, "1/60 s"},       {"Substeps", 0, "8"},
               {"Iterations", 0, "4"},        {"Damping", 0, "0.995"},         {"Gravity", 0, "0.5 u/s^2"}};
    t.total_label = "TOTAL";
    t.total_value = "1 SIMULATION";
    t.thanks = {"THANK YOU FOR SIMULATING!", "Grab, crumple, fold, toss."};
    t.barcode = "240040600860";
    return t;
  }
  t.header = "PHYSICS DINER";
  t.address = {"42 Verlet Lane, Springfield", "Tel 555-0199 \xc2\xb7 Table 7"};
  t.items = {{"Constraint Burger", 1250, ""}, {"Verlet Fries", 475, ""},     {"Spring Salad", 895, ""},
             {"Damped Soup", 650, ""},        {"Hash Grid Nachos", 725, ""}, {"Tear-Apart Bread", 395, ""},
             {"Substep Shake", 550, ""},      {"Gravity Pie", 480, ""},      {"Espresso x2", 560, ""}};
  uint32_t sum = 0;
  for (auto& it : t.items) sum += it.cents;
  t.total_label = "TOTAL";
  t.total_value = formatPrice(sum);
  t.thanks = {"THANK YOU FOR DINING WITH US!", "Please come again"};
  t.barcode = "4006381333931";
  return t;
}

std::string receiptFontPath() {
  const char* font = std::getenv("TENDER_FONT");
  return font && *font ? font : kReceiptFont;
}

ReceiptImage rasterizeReceipt(const ReceiptText& text, uint32_t width, const std::string& font_path) {
  Font font(font_path);
  ReceiptImage img;
  img.width = std::max(width, 64u);
  img.height = img.width * 3 / 2;
  img.rgba.resize(size_t(img.width) * img.height * 4);
  for (size_t i = 0; i < size_t(img.width) * img.height; ++i) {
    img.rgba[i * 4 + 0] = kPaper[0];
    img.rgba[i * 4 + 1] = kPaper[1];
    img.rgba[i * 4 + 2] = kPaper[2];
    img.rgba[i * 4 + 3] = 255;
  }
  Printer p(img, font);
  int y = 78;
  p.text(text.header, 38, -1, y, true);
  y += 36;
  for (auto& a : text.address) {
    p.text(a, 17, -1, y);
    y += 24;
  }
  y += 6;
  p.dashes(y);
  y += 40;
  for (auto& it : text.items) {
    p.columns(it.name, it.value.empty() ? formatPrice(it.cents) : it.value, 19, y);
    y += 31;
  }
  y += 2;
  p.dashes(y - 12);
  y += 30;
  p.columns(text.total_label, text.total_value, 25, y, true);
  y += 24;
  p.dashes(y);
  y += 44;
  for (auto& l : text.thanks) {
    p.text(l, 18, -1, y);
    y += 26;
  }
  y += 10;
  const int bar_bottom = int(kReceiptLayoutWidth * 3 / 2) - 44;
  p.barcode(text.barcode, y, bar_bottom);
  std::string spaced;
  for (char c : text.barcode) spaced += c, spaced += ' ';
  if (!spaced.empty()) spaced.pop_back();
  p.text(spaced, 15, -1, bar_bottom + 22);
  return img;
}

} // namespace tender::render
