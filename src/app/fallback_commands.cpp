// Commands of a build without the renderer: the main job falls back to `tender sim`.
#include <cstdio>

#include "commands.h"

namespace tender {

int runRender(const CommonOptions&, const RenderOptions&) {
  return fail("this build has no renderer (configure with TENDER_VULKAN=ON)");
}

const char* const kProgramName = "tender";

int runDemo(const CommonOptions& common, const DemoOptions&) {
  std::printf("tender: no renderer in this build; running the simulation headless\n");
  SimOptions o;
  o.ticks = 240;
  return runSim(common, o);
}

#ifndef TENDER_HAS_GPU
int runDevices(const CommonOptions&) { return fail("this build has no Vulkan backend"); }
#endif

} // namespace tender
