#pragma once
/// What one compute dispatch costs on a device, apart from any work: a chain of empty dispatches,
/// each followed by the compute-to-compute pipeline barrier the solver puts between its passes,
/// timed with timestamp queries. A per-colour tick is hundreds of such dispatches, the fused
/// small-sheet tick a few, so this cost says how much the fused tick saves on a device.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "gpu/context.h"

namespace tender::bench {

/// Empty dispatches per timed chain, and timed chains.
constexpr uint32_t kDispatchChain = 1000;
constexpr uint32_t kDispatchRepetitions = 3;

/// A measured dispatch cost.
struct DispatchCost {
  double us = 0.0;                ///< microseconds per dispatch + barrier: the median over the chains
  uint32_t chain = 0;             ///< dispatches per timed chain
  uint32_t repetitions = 0;       ///< timed chains
  std::vector<double> samples_us; ///< each chain's time over its length, in the order they ran
  std::string method;             ///< how it was measured, in words
};

/// Records, in one command buffer, an untimed chain a tenth as long and then `repetitions` timed
/// chains of `chain` dispatches of the empty shader (one workgroup of 64 invocations), each
/// dispatch followed by gpu::computeToCompute, a timestamp before and after each chain. nullopt and
/// a one-line `error` when the queue has no timestamps or Vulkan fails.
std::optional<DispatchCost> measureDispatchCost(gpu::VulkanContext& ctx, std::string& error,
                                                uint32_t chain = kDispatchChain,
                                                uint32_t repetitions = kDispatchRepetitions);

} // namespace tender::bench
