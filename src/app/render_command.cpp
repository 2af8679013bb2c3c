// `tender render`: a preset after N ticks, rendered offscreen to a PNG (no window, no display).
#include <cstdio>

#include "backend/headless.h"
#include "commands.h"
#include "core/output.h"

namespace tender {

void headlessOptionsFor(const CommonOptions& common, const RenderOptions& o, const InputScript& script,
                        render::HeadlessOptions& out) {
  out.params = common.params;
  out.backend = common.backend;
  out.device = common.device;
  out.validation = common.validation;
  out.width = o.width;
  out.height = o.height;
  out.script = script;
}

int runRender(const CommonOptions& common, const RenderOptions& o) {
  if (!o.video.empty()) return runVideo(common, o);
  OutputSet outputs;
  if (auto err = outputs.add(o.out)) return fail(*err);
  std::string error;
  auto script = scriptFor(common.script, common.params, common.backend, error);
  if (!script) return fail(error);
  render::HeadlessOptions h;
  headlessOptionsFor(common, o, *script, h);
  h.ticks = o.ticks;
  render::HeadlessResult r = render::renderHeadless(h);
  if (!r.error.empty()) return fail(r.error);
  if (auto err = outputs.stage(o.out, render::encodePng(r.picture))) return fail(*err);
  if (auto err = outputs.commit()) return fail(*err);
  std::printf("tender render: %s (%ux%u, preset %s, %llu ticks, backend %s)\n", o.out.c_str(), o.width, o.height,
              common.params.preset.c_str(), static_cast<unsigned long long>(o.ticks), common.backend.c_str());
  if (common.validation && r.validation_messages > 0)
    return fail(std::to_string(r.validation_messages) + " validation messages");
  return 0;
}

} // namespace tender
