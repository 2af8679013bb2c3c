// tender-icon: writes the window icon (src/app/demo/window_icon.cpp, drawn in code) as PNG files, for the
// installed desktop entry. Usage: tender-icon OUT_DIR SIZE... writes OUT_DIR/SIZExSIZE/apps/tender.png.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <stb/stb_image_write.h>

#include "demo/window_icon.h"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: tender-icon OUT_DIR SIZE...\n");
    return 2;
  }
  for (int i = 2; i < argc; ++i) {
    const int size = std::atoi(argv[i]);
    if (size < 8 || size > 1024) {
      std::fprintf(stderr, "tender-icon: error: bad size '%s' (8 to 1024)\n", argv[i]);
      return 2;
    }
    const std::string s = std::to_string(size);
    const std::filesystem::path dir = std::filesystem::path(argv[1]) / (s + "x" + s) / "apps";
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    const std::string file = (dir / "tender.png").string();
    const auto px = tender::demo::drawPaperIcon(size);
    if (ec || !stbi_write_png(file.c_str(), size, size, 4, px.data(), size * 4)) {
      std::fprintf(stderr, "tender-icon: error: cannot write %s\n", file.c_str());
      return 2;
    }
  }
  return 0;
}
