#include "backend.h"

#include <algorithm>
#include <exception>

#include "cpu/cpu_batch.h"
#include "cpu/cpu_solver.h"
#ifdef TENDER_HAS_GPU
#include "gpu/gpu_batch.h"
#include "gpu/gpu_solver.h"
#endif

namespace tender {

#ifdef TENDER_HAS_GPU
namespace {

/// A Vulkan context of the options' device (and validation); one line on failure.
std::optional<std::string> createContext(const BackendOptions& o, std::unique_ptr<gpu::VulkanContext>& out) {
  gpu::ContextOptions co;
  co.device = o.device;
  co.validation = o.validation;
  auto ctx = gpu::VulkanContext::create(co);
  if (!ctx) return ctx.error() + " (try --backend cpu)";
  out = std::move(ctx.value());
  return std::nullopt;
}

/// The fused tick's shape the options ask for (the rest is the device kind's).
gpu::FusedShape fusedShapeOf(const BackendOptions& o) {
  gpu::FusedShape shape;
  shape.workgroup = o.fused_workgroup;
  return shape;
}

} // namespace
#endif

BackendOptions backendOptionsFor(const std::string& backend, const SimParams& params) {
  BackendOptions o;
  o.backend = backend;
  o.threads = params.threads;
  o.simd = params.simd;
  return o;
}

std::vector<std::string> backendNames() { return {"cpu", "gpu", "gpu-percolor"}; }

bool vulkanBuilt() {
#ifdef TENDER_HAS_GPU
  return true;
#else
  return false;
#endif
}

std::optional<std::string> createBackend(const BackendOptions& o, Backend& out) {
  out = Backend{};
  if (o.backend == "cpu") {
    if (o.time_kernels) return std::string("kernel times are a GPU backend's (the cpu backend runs no kernels)");
    CpuOptions co;
    co.threads = o.threads;
    co.min_chunk = o.min_chunk;
    co.simd = o.simd;
    auto cpu = std::make_unique<CpuSolver>(co);
    cpu->setPlantedUlp(o.plant);
    out.cpu = cpu.get();
    out.solver = std::move(cpu);
    return std::nullopt;
  }
  if (o.backend != "gpu" && o.backend != "gpu-percolor") return "unknown backend '" + o.backend + "' (cpu or gpu)";
#ifdef TENDER_HAS_GPU
  try {
    std::unique_ptr<gpu::GpuSolver> solver;
    std::unique_ptr<gpu::VulkanContext> ctx;
    if (o.context) {
      solver = std::make_unique<gpu::GpuSolver>(*o.context, fusedShapeOf(o));
    } else if (auto err = createContext(o, ctx)) {
      return err;
    } else {
      solver = std::make_unique<gpu::GpuSolver>(std::move(ctx), fusedShapeOf(o));
    }
    if (o.backend == "gpu-percolor") solver->setFusedPath(false);
    solver->timeKernels(o.time_kernels);
    out.gpu = solver.get();
    out.solver = std::move(solver);
  } catch (const std::exception& e) {
    out = Backend{};
    return e.what();
  }
  return std::nullopt;
#else
  return std::string("this build has no Vulkan backend (try --backend cpu)");
#endif
}

std::optional<std::string> createSharedContext([[maybe_unused]] const BackendOptions& o,
                                               std::shared_ptr<gpu::VulkanContext>& out) {
  out.reset();
#ifdef TENDER_HAS_GPU
  try {
    std::unique_ptr<gpu::VulkanContext> ctx;
    if (auto err = createContext(o, ctx)) return err;
    out = std::move(ctx);
  } catch (const std::exception& e) {
    return e.what();
  }
  return std::nullopt;
#else
  return std::string("this build has no Vulkan backend (try --backend cpu)");
#endif
}

uint64_t gpuMemoryBytes([[maybe_unused]] int device) {
#ifdef TENDER_HAS_GPU
  auto devices = gpu::listDevices();
  if (!devices) return 0;
  const gpu::DeviceInfo* chosen = nullptr;
  for (const gpu::DeviceInfo& d : *devices)
    if (device >= 0 ? int(d.index) == device : d.usable && (!chosen || d.preference < chosen->preference)) chosen = &d;
  return chosen ? chosen->memory_bytes : 0;
#else
  return 0;
#endif
}

BatchFit batchFit(const SimParams& p, const std::string& backend, int device) {
  BatchFit f;
  const std::string kind = backend == "cpu" ? "cpu" : "gpu";
  f.per_sheet = std::max<uint64_t>(1, estimateSheetBytes(p, kind));
  uint64_t memory = availableMemoryBytes();
  if (kind == "gpu")
    if (const uint64_t device_bytes = gpuMemoryBytes(device)) memory = std::min(memory, device_bytes);
  f.budget = memoryBudget(memory);
  f.fit = f.budget / f.per_sheet;
  return f;
}

std::optional<std::string> batchMemoryError(const SimParams& p, const std::string& backend, uint64_t sheets,
                                            int device) {
  const BatchFit f = batchFit(p, backend, device);
  if (sheets <= f.fit) return std::nullopt;
  const uint64_t need = sheets > UINT64_MAX / f.per_sheet ? UINT64_MAX : sheets * f.per_sheet;
  return "a batch of " + std::to_string(sheets) + " " + std::to_string(p.cols) + "x" + std::to_string(p.rows) +
         " sheets needs about " + std::to_string(need >> 20) + " MiB on the " + (backend == "cpu" ? "cpu" : "gpu") +
         " backend; " + std::to_string(f.budget >> 20) + " MiB are available";
}

std::optional<std::string> createBatch(const BackendOptions& o, uint32_t sheets, std::unique_ptr<SheetBatch>& out) {
  out.reset();
  if (sheets == 0) return std::string("a batch needs at least one sheet");
  if (o.backend == "cpu") {
    CpuOptions co;
    co.simd = o.simd;
    out = std::make_unique<CpuBatch>(sheets, o.threads, co);
    return std::nullopt;
  }
  if (o.backend != "gpu") return "a fleet runs on cpu or gpu, not '" + o.backend + "'";
#ifdef TENDER_HAS_GPU
  try {
    std::unique_ptr<gpu::VulkanContext> ctx;
    if (o.context) {
      out = std::make_unique<gpu::GpuBatch>(*o.context, sheets, gpu::BatchPasses::Auto, fusedShapeOf(o));
    } else if (auto err = createContext(o, ctx)) {
      return err;
    } else {
      out = std::make_unique<gpu::GpuBatch>(std::move(ctx), sheets, fusedShapeOf(o));
    }
  } catch (const std::exception& e) {
    out.reset();
    return e.what();
  }
  return std::nullopt;
#else
  return std::string("this build has no Vulkan backend (try --backend cpu)");
#endif
}

} // namespace tender
