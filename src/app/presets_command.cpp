// `tender presets`: the built-in presets by name, or one of them as a preset file (JSON).
#include <cstdio>

#include "commands.h"

namespace tender {

int runPresets(const std::string& name) {
  if (name.empty()) {
    for (const std::string& n : presetNames()) std::printf("%s\n", n.c_str());
    return 0;
  }
  std::optional<SimParams> p = presetParams(name);
  if (!p) return fail(unknownPreset(name));
  const std::string text = presetJson(*p);
  if (std::fwrite(text.data(), 1, text.size(), stdout) != text.size() || std::fflush(stdout) != 0)
    return fail("cannot write the preset to standard output");
  return 0;
}

} // namespace tender
