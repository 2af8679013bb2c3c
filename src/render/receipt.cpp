#include "receipt.h"

#include <algorithm>
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
// Left and right margin in pixels.
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

class Printer {
public:
  Printer(ReceiptImage& img, Font& font) : img_(img), font_(font) {}

  // Blends ink over the paper at (x, y) with coverage a (0..255).
  void ink(int x, int y, uint32_t a) {
    if (x < 0 || y < 0 || x >= int(img_.width) || y >= int(img_.height) || a == 0) return;
    uint8_t* p = &img_.rgba[(size_t(y) * img_.width + size_t(x)) * 4];
    for (int c = 0; c < 3; ++c) p[c] = uint8_t((p[c] * (255 - a) + kInk[c] * a + 127) / 255);
  }

  // Prints text with its baseline at y; x < 0 centres it. Returns the printed line.
  PrintedLine text(const std::string& s, int px, int x, int baseline, bool bold = false) {
    font_.setSize(px);
    int adv = font_.advance();
    int w = int(codepointCount(s)) * adv;
    if (x < 0) x = (int(img_.width) - w) / 2;
    FT_Face f = font_.face();
    int pen = x;
    for (size_t i = 0; i < s.size();) {
      uint32_t cp = nextCodepoint(s, i);
      if (FT_Load_Char(f, cp, FT_LOAD_RENDER)) continue;
      const FT_Bitmap& bm = f->glyph->bitmap;
      for (int pass = 0; pass < (bold ? 2 : 1); ++pass) // bold: print twice, one pixel apart
        for (unsigned r = 0; r < bm.rows; ++r)
          for (unsigned c = 0; c < bm.width; ++c)
            ink(pen + f->glyph->bitmap_left + int(c) + pass, baseline - f->glyph->bitmap_top + int(r),
                bm.buffer[r * unsigned(bm.pitch) + c]);
      pen += int(f->glyph->advance.x >> 6);
    }
    PrintedLine l{s, x, baseline - px * 3 / 4, x + w, baseline + px / 4};
    img_.lines.push_back(l);
    return l;
  }

  // Prints `left` at the left margin and `right` flush with the right margin.
  void columns(const std::string& left, const std::string& right, int px, int baseline, bool bold = false) {
    text(left, px, kMargin, baseline, bold);
    font_.setSize(px);
    int w = int(codepointCount(right)) * font_.advance();
    text(right, px, int(img_.width) - kMargin - w, baseline, bold);
  }

  void dashes(int y) {
    for (int x = kMargin; x < int(img_.width) - kMargin; ++x)
      if ((x - kMargin) % 12 < 7)
        for (int t = 0; t < 2; ++t) ink(x, y + t, 255);
    img_.lines.push_back({"----", kMargin, y, int(img_.width) - kMargin, y + 2});
  }

  // A faux barcode: bar widths from the digits, framed by guard bars.
  void barcode(const std::string& digits, int y0, int y1) {
    std::vector<int> widths = {1, 1, 1, 1}; // start guard: bar, space, bar, space
    for (char ch : digits) {
      int d = ch - '0';
      int pattern[4] = {1 + d % 3, 1 + (d + 1) % 2, 1 + (d * 7) % 4, 1 + (d + 2) % 3};
      widths.insert(widths.end(), pattern, pattern + 4);
    }
    widths.insert(widths.end(), {1, 1, 1});
    int total = 0;
    for (int w : widths) total += w;
    const int module = std::max(1, (int(img_.width) - 2 * kMargin - 40) / total);
    int x = (int(img_.width) - total * module) / 2;
    const int x_start = x;
    for (size_t k = 0; k < widths.size(); ++k) {
      if (k % 2 == 0)
        for (int xx = x; xx < x + widths[k] * module; ++xx)
          for (int y = y0; y < y1; ++y) ink(xx, y, 255);
      x += widths[k] * module;
    }
    img_.lines.push_back({"|||", x_start, y0, x, y1});
  }

private:
  ReceiptImage& img_;
  Font& font_;
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

ReceiptImage rasterizeReceipt(const ReceiptText& text, const std::string& font_path) {
  Font font(font_path);
  ReceiptImage img;
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
  const int bar_bottom = int(img.height) - 44;
  p.barcode(text.barcode, y, bar_bottom);
  std::string spaced;
  for (char c : text.barcode) spaced += c, spaced += ' ';
  if (!spaced.empty()) spaced.pop_back();
  p.text(spaced, 15, -1, bar_bottom + 22);
  return img;
}

} // namespace tender::render
