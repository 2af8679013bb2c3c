#pragma once
/// The one way every program (tender sim, render, the demo, tender-bench, the tests) builds a
/// solver: the CPU reference on the threads the parameters ask for, or the Vulkan compute solver
/// on its own or on a shared context.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/fleet.h"
#include "core/params.h"
#include "core/passes.h"
#include "core/solver.h"

namespace tender {

class CpuSolver;
namespace gpu {
class GpuSolver;
class VulkanContext;
} // namespace gpu

/// What to build.
struct BackendOptions {
  /// "cpu"; "gpu"; or "gpu-percolor", the GPU solver without its fused small-sheet tick.
  std::string backend = "gpu";
  int device = -1;                 ///< Vulkan device index (`tender devices`), -1 = prefer a discrete GPU
  bool validation = false;         ///< VK_LAYER_KHRONOS_validation with synchronization validation
  uint32_t threads = 0;            ///< CPU solver workers (SimParams::threads): 0 = one per hardware thread
  uint32_t min_chunk = 0;          ///< CPU solver: smallest loop share worth a thread; 0 = tuned (CpuOptions)
  bool simd = true;                ///< CPU solver SIMD kernels (SimParams::simd)
  std::optional<PlantedUlp> plant; ///< CPU solver: the test hook of `tender diff` (CpuSolver::setPlantedUlp)
  /// GPU solver and fleet: invocations of the fused tick's workgroup, at most SIM_WG_FUSED_MAX and
  /// the device's limit (FusedShape::workgroup); 0 = the device kind's (`tender-bench
  /// --fused-workgroup`)
  uint32_t fused_workgroup = 0;
  /// GPU solver: time each dispatch apart (GpuSolver::timeKernels; `tender sim --kernel-times`)
  bool time_kernels = false;
  /// Run the GPU solver on this context (the renderer's) instead of creating one; it must outlive
  /// the backend.
  gpu::VulkanContext* context = nullptr;
};

/// A solver, and the concrete solver behind it for what only that backend offers (the renderer
/// draws the GPU solver's buffers; tools read the CPU solver's thread count).
struct Backend {
  std::unique_ptr<Solver> solver;
  CpuSolver* cpu = nullptr;      ///< the solver, when it is the CPU reference
  gpu::GpuSolver* gpu = nullptr; ///< the solver, when it runs on Vulkan
};

/// Options of a backend for a sheet of these parameters: its CPU threads and SIMD switch.
BackendOptions backendOptionsFor(const std::string& backend, const SimParams& params);

/// The backend names createBackend takes.
std::vector<std::string> backendNames();
/// True when this build has the Vulkan backend.
bool vulkanBuilt();

/// Builds a backend; on failure returns one line (an unknown name, no Vulkan device, a Vulkan
/// error) and leaves `out` empty.
std::optional<std::string> createBackend(const BackendOptions& options, Backend& out);

/// A Vulkan context of the options' device (and validation) for solvers and batches to share
/// (BackendOptions::context): each compiles the simulation's kernels once a context. On failure
/// returns the line createBackend gives and leaves `out` empty.
std::optional<std::string> createSharedContext(const BackendOptions& options, std::shared_ptr<gpu::VulkanContext>& out);

/// Bytes of device-local memory of Vulkan device `device` (-1: the one a solver given no index
/// takes); 0 when it is unknown (no such device, or no Vulkan).
uint64_t gpuMemoryBytes(int device);

/// Most sheets of one batch: a GPU dispatch's workgroup count limit.
constexpr uint32_t kMaxBatchSheets = 65535;

/// How many sheets of `p` fit a batch on a backend ("cpu" or a GPU backend): the memory available
/// (and on a GPU backend the device's, `device` as gpuMemoryBytes takes it) with a tenth to spare.
struct BatchFit {
  uint64_t per_sheet = 1; ///< bytes of one sheet (estimateSheetBytes)
  uint64_t budget = 0;    ///< bytes the batch may take
  uint64_t fit = 0;       ///< sheets that fit the budget
};
BatchFit batchFit(const SimParams& p, const std::string& backend, int device);
/// "a batch of N WxH sheets needs about X MiB on the B backend; Y MiB are available" when
/// `sheets` sheets do not fit; nullopt when they do.
std::optional<std::string> batchMemoryError(const SimParams& p, const std::string& backend, uint64_t sheets,
                                            int device);

/// Builds the batch of a fleet of `sheets` sheets ("cpu" or "gpu"; `threads` and `simd` for the
/// CPU's workers and kernels); on failure returns one line and leaves `out` empty.
std::optional<std::string> createBatch(const BackendOptions& options, uint32_t sheets,
                                       std::unique_ptr<SheetBatch>& out);

} // namespace tender
