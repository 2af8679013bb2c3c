#include "headless.h"

#include <memory>

#include "core/simulation.h"
#include "cpu/cpu_solver.h"
#include "gpu/gpu_solver.h"
#include "paper_mesh.h"

namespace tender::render {

PaperBuffers gpuPaperBuffers(gpu::GpuSolver& solver) {
  return {solver.positionBuffer(), solver.normalBuffer(),  solver.uvBuffer(),
          solver.triangleBuffer(), solver.counterBuffer(), gpu::GpuSolver::kDrawArgsOffset};
}

HeadlessResult renderHeadless(const HeadlessOptions& o) {
  HeadlessResult result;
  gpu::ContextOptions co;
  co.device = o.device;
  co.validation = o.validation;
  co.quiet = o.quiet;
  co.graphics = true;
  auto created = gpu::VulkanContext::create(co);
  if (!created) {
    result.error = created.error();
    return result;
  }
  std::unique_ptr<gpu::VulkanContext> ctx = std::move(created.value());
  {
    // The receipt first: a missing font is reported before any work.
    ReceiptImage receipt = rasterizeReceipt(receiptText(o.params.preset));
    std::unique_ptr<Solver> solver;
    if (o.backend == "cpu")
      solver = std::make_unique<CpuSolver>();
    else
      solver = std::make_unique<gpu::GpuSolver>(*ctx);
    Simulation sim(o.params, *solver);
    sim.setScript(o.script);
    for (uint64_t t = 0; t < o.ticks; ++t) sim.tick();
    solver->computeNormals();

    RendererOptions ro;
    ro.color_format = OffscreenTarget::kFormat;
    ro.final_layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    ro.frames = 1;
    Renderer renderer(*ctx, ro, receipt);
    renderer.buildAll();
    std::unique_ptr<HostPaperMesh> host;
    if (auto* g = dynamic_cast<gpu::GpuSolver*>(solver.get())) {
      g->finish();
      renderer.setPaper(0, gpuPaperBuffers(*g));
    } else {
      SimState state;
      solver->readback(state);
      host = std::make_unique<HostPaperMesh>(*ctx, sim.topology());
      host->update(state);
      renderer.setPaper(0, host->buffers());
    }
    OffscreenTarget target(*ctx, renderer, o.width, o.height);
    result.picture = target.render(defaultSceneView(sim.params()));
    ctx->waitIdle();
  }
  result.validation_messages = ctx->validationMessages();
  return result;
}

} // namespace tender::render
