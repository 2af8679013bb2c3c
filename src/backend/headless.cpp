#include "headless.h"

#include <exception>
#include <memory>

#include "backend.h"
#include "core/sheet.h"
#include "core/simulation.h"
#include "gpu/gpu_solver.h"
#include "render/paper_mesh.h"

namespace tender::render {

std::optional<std::string> renderSequence(const HeadlessOptions& o, const FrameSequence& seq,
                                          uint32_t* validation_messages, std::string* device) {
  gpu::ContextOptions co;
  co.device = o.device;
  co.validation = o.validation;
  co.quiet = o.quiet;
  co.graphics = true;
  auto created = gpu::VulkanContext::create(co);
  if (!created) return created.error();
  std::unique_ptr<gpu::VulkanContext> ctx = std::move(created.value());
  if (device) *device = ctx->info().name;
  try {
    // The receipt first: a missing font is reported before any work.
    ReceiptImage receipt = rasterizeReceipt(receiptText(o.params.preset));
    BackendOptions bo = backendOptionsFor(o.backend, o.params);
    bo.context = ctx.get();
    Backend backend;
    if (auto err = createBackend(bo, backend)) return *err;
    Solver& solver = *backend.solver;
    Simulation sim(o.params, solver);
    sim.setScript(o.script);

    RendererOptions ro;
    ro.color_format = OffscreenTarget::kFormat;
    ro.final_layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    ro.frames = 1;
    Renderer renderer(*ctx, ro, receipt);
    renderer.buildAll();
    std::unique_ptr<HostPaperMesh> host;
    if (backend.gpu)
      renderer.setPaper(0, gpuPaperBuffers(*backend.gpu));
    else
      host = std::make_unique<HostPaperMesh>(*ctx, sim.topology());
    if (host) renderer.setPaper(0, host->buffers());
    OffscreenTarget target(*ctx, renderer, o.width, o.height);
    SceneView view = defaultSceneView(sim.params());
    const std::vector<uint32_t> samples = sheetSamples(sim.topology());
    uint64_t ticks = 0;
    SimState state;
    for (uint64_t frame = 0; frame < seq.frames; ++frame) {
      for (const uint64_t due = seq.ticks_before(frame); ticks < due; ++ticks) sim.tick();
      solver.computeNormals();
      solver.finish();
      if (host) {
        solver.readback(state);
        host->update(state);
      }
      if (view.sheet_share > 0.0f) followSheet(view, solver.particlePositions(samples));
      if (auto err = seq.sink(target.render(view), frame)) {
        ctx->waitIdle();
        return err;
      }
    }
    ctx->waitIdle();
  } catch (const std::exception& e) {
    return std::string(e.what());
  }
  if (validation_messages) *validation_messages = ctx->validationMessages();
  return std::nullopt;
}

HeadlessResult renderHeadless(const HeadlessOptions& o) {
  HeadlessResult result;
  FrameSequence one;
  one.frames = 1;
  one.ticks_before = [&](uint64_t) { return o.ticks; };
  one.sink = [&](const Picture& picture, uint64_t) -> std::optional<std::string> {
    result.picture = picture;
    return std::nullopt;
  };
  if (auto err = renderSequence(o, one, &result.validation_messages, &result.device)) result.error = *err;
  return result;
}

} // namespace tender::render
