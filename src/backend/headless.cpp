#include "headless.h"

#include <exception>
#include <memory>

#include "backend.h"
#include "core/simulation.h"
#include "gpu/gpu_solver.h"
#include "render/paper_mesh.h"

namespace tender::render {

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
  try {
    // The receipt first: a missing font is reported before any work.
    ReceiptImage receipt = rasterizeReceipt(receiptText(o.params.preset));
    BackendOptions bo = backendOptionsFor(o.backend, o.params);
    bo.context = ctx.get();
    Backend backend;
    if (auto err = createBackend(bo, backend)) {
      result.error = *err;
      return result;
    }
    Solver& solver = *backend.solver;
    Simulation sim(o.params, solver);
    sim.setScript(o.script);
    for (uint64_t t = 0; t < o.ticks; ++t) sim.tick();
    solver.computeNormals();
    solver.finish();

    RendererOptions ro;
    ro.color_format = OffscreenTarget::kFormat;
    ro.final_layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    ro.frames = 1;
    Renderer renderer(*ctx, ro, receipt);
    renderer.buildAll();
    std::unique_ptr<HostPaperMesh> host;
    if (backend.gpu) {
      renderer.setPaper(0, gpuPaperBuffers(*backend.gpu));
    } else {
      SimState state;
      solver.readback(state);
      host = std::make_unique<HostPaperMesh>(*ctx, sim.topology());
      host->update(state);
      renderer.setPaper(0, host->buffers());
    }
    OffscreenTarget target(*ctx, renderer, o.width, o.height);
    result.picture = target.render(defaultSceneView(sim.params()));
    ctx->waitIdle();
  } catch (const std::exception& e) {
    result.error = e.what();
    return result;
  }
  result.validation_messages = ctx->validationMessages();
  return result;
}

} // namespace tender::render
