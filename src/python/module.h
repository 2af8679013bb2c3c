#pragma once
/// The module's parts: the GPU contexts its objects share, and the Fleet class (fleet.cpp).
#include <map>
#include <memory>

#include <pybind11/pybind11.h>

#include "backend/backend.h"

namespace tender {

namespace gpu {
class VulkanContext;
}

/// One Vulkan context a device for every GPU Simulation and Fleet of the process (module.cpp).
std::map<int, std::shared_ptr<gpu::VulkanContext>>& contextCache();
/// The shared context of `options`' device, made at first use; RuntimeError when there is none.
std::shared_ptr<gpu::VulkanContext> sharedContext(const BackendOptions& options);
/// Adds tender.Fleet to the module.
void bindFleet(pybind11::module_& m);

} // namespace tender
