// `tender render`: a preset after N ticks, rendered offscreen to a PNG (no window, no display).
#include <cstdio>

#include "commands.h"
#include "render/headless.h"

namespace tender {

int runRender(const CommonOptions& common, const RenderOptions& o) {
  render::HeadlessOptions h;
  h.params = common.params;
  h.backend = common.backend;
  h.device = common.device;
  h.validation = common.validation;
  h.ticks = o.ticks;
  h.width = o.width;
  h.height = o.height;
  if (!common.script.empty()) {
    std::string error;
    auto s = loadScript(common.script, error);
    if (!s) return fail(error);
    h.script = *s;
  }
  render::HeadlessResult r = render::renderHeadless(h);
  if (!r.error.empty()) return fail(r.error);
  if (!render::writePng(o.out, r.picture)) return fail("cannot write '" + o.out + "'");
  std::printf("tender render: %s (%ux%u, preset %s, %llu ticks, backend %s)\n", o.out.c_str(), o.width, o.height,
              common.params.preset.c_str(), static_cast<unsigned long long>(o.ticks), common.backend.c_str());
  if (common.validation && r.validation_messages > 0) {
    std::fprintf(stderr, "tender render: %u validation messages\n", r.validation_messages);
    return 1;
  }
  return 0;
}

} // namespace tender
