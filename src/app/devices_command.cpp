// `tender devices`: the Vulkan devices, in the order --device numbers them.
#include <cstdio>

#include "commands.h"
#include "gpu/context.h"
#include "gpu/sim_pipeline.h"

namespace tender {

int runDevices(const CommonOptions&) {
  auto devices = gpu::listDevices();
  if (!devices) return fail(devices.error() + " (try --backend cpu)");
  int best = -1, best_rank = 1 << 30;
  for (const gpu::DeviceInfo& d : *devices) {
    int rank = d.type == "discrete"     ? 0
               : d.type == "integrated" ? 1
               : d.type == "virtual"    ? 2
               : d.type == "cpu"        ? 3
                                        : 4;
    if (d.usable && rank < best_rank) {
      best_rank = rank;
      best = int(d.index);
    }
  }
  for (const gpu::DeviceInfo& d : *devices) {
    std::printf("%c %u: %s (%s), Vulkan %u.%u.%u, driver %s, %.1f GiB%s\n", int(d.index) == best ? '*' : ' ', d.index,
                d.name.c_str(), d.type.c_str(), VK_API_VERSION_MAJOR(d.api_version),
                VK_API_VERSION_MINOR(d.api_version), VK_API_VERSION_PATCH(d.api_version), d.driver.c_str(),
                double(d.memory_bytes) / (1024.0 * 1024.0 * 1024.0), d.usable ? "" : " [not usable: needs Vulkan 1.3]");
    // What the simulation's shaders ask of its float arithmetic (shaders/spirv/spirv_rules.h)
    const gpu::FloatRules rules = gpu::floatRulesFor(d.floats);
    // A CPU device may flush them with the host's FTZ and DAZ instead (gpu::simFloatRules: a probe)
    const bool host = d.type == "cpu" && rules.denormals == gpu::Denormals::FlushInShader;
    std::printf("    float32 controls: round to nearest even %s, denormal preserve %s, flush %s -> denormals %s%s; "
                "subgroup %u, shared memory %u KiB (the fused tick: sheets of up to %u particles)\n",
                d.floats.rounding_rte ? "yes" : "no", d.floats.denorm_preserve ? "yes" : "no",
                d.floats.denorm_flush ? "yes" : "no", gpu::denormalsName(rules.denormals),
                host ? ", or with the host's FTZ and DAZ where its threads have them" : "", d.subgroup_size,
                d.shared_memory / 1024u, gpu::fusedCapacity(d.shared_memory));
  }
  std::printf("(* = used by default; choose another with --device N)\n");
  return 0;
}

} // namespace tender
