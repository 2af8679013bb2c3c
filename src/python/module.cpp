// `import tender`: the simulation from Python (pybind11). The same controller, solvers, stats and
// writers as `tender sim`, so the same run gives the same state hash.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "backend/backend.h"
#include "core/fleet.h"
#include "core/output.h"
#include "core/params.h"
#include "core/script.h"
#include "core/simulation.h"
#include "core/stats.h"
#include "export/gltf.h"
#include "python/convert.h"
#include "python/module.h"
#ifdef TENDER_HAS_GPU
#include "gpu/context.h"
#endif

namespace py = pybind11;

namespace tender {

/// One Vulkan context a device for every GPU Simulation and Fleet of the process: each compiles
/// the simulation's kernels once a context (VulkanContext::sharedPipeline), on lavapipe seconds,
/// so once a process rather than once an object. Every call holds the GIL: no two objects use a
/// context at once. Each object holds its context as well, so a context outlives its solvers; the
/// cache lets go of its own at exit (atexit), while the driver is still loaded.
std::map<int, std::shared_ptr<gpu::VulkanContext>>& contextCache() {
  static std::map<int, std::shared_ptr<gpu::VulkanContext>> cache;
  return cache;
}

/// The shared context of `options`' device, made at first use; RuntimeError when there is none.
std::shared_ptr<gpu::VulkanContext> sharedContext(const BackendOptions& options) {
  auto& cache = contextCache();
  if (auto it = cache.find(options.device); it != cache.end()) return it->second;
  std::shared_ptr<gpu::VulkanContext> ctx;
  if (auto err = createSharedContext(options, ctx)) raise(PyExc_RuntimeError, *err);
  cache[options.device] = ctx;
  return ctx;
}

namespace {

class PySimulation {
public:
  PySimulation(const std::optional<std::string>& preset, const std::string& backend, std::optional<int> device,
               const std::optional<std::string>& preset_file, const py::kwargs& params) {
    SimParams p = baseParams(preset, preset_file);
    for (auto item : params) applyKey(p, keyOf(item.first, "params"), item.second);
    if (backend != "cpu" && backend != "gpu") raise(PyExc_ValueError, "unknown backend '" + backend + "' (cpu or gpu)");
    if (device && *device < 0) raise(PyExc_ValueError, "device: expected an index >= 0 (see tender.devices())");
    if (auto err = validate(p, backend)) raise(PyExc_ValueError, *err);
    backend_name_ = backend;
    device_ = device.value_or(-1);
    build(p);
  }

  void step(int64_t ticks) {
    if (ticks < 0) raise(PyExc_ValueError, "ticks: expected a count >= 0, got " + std::to_string(ticks));
    for (int64_t t = 0; t < ticks; ++t) {
      auto t0 = std::chrono::steady_clock::now();
      const bool ran = sim_->tick();
      if (ran) backend_.solver->finish();
      auto t1 = std::chrono::steady_clock::now();
      if (ran) ms_.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
      if ((t & 15) == 15 && PyErr_CheckSignals() != 0) throw py::error_already_set();
    }
    backend_.solver->finish();
  }

  void grab(int64_t particle) {
    const uint32_t n = sim_->topology().particleCount();
    if (particle < 0 || particle >= int64_t(n))
      raise(PyExc_ValueError,
            "particle " + std::to_string(particle) + " does not exist (the sheet has " + std::to_string(n) + ")");
    sim_->grabParticle(uint32_t(particle));
  }

  bool grabRay(const py::sequence& origin, const py::sequence& direction) {
    glm::vec3 o = sequence3(origin, "origin"), d = sequence3(direction, "direction");
    if (!(glm::dot(d, d) > 0.0f)) raise(PyExc_ValueError, "direction: expected a non-zero vector");
    return sim_->grabRay(o, d);
  }

  void move(double x, double y, double z) { sim_->moveGrab(coordinates(x, y, z, "move")); }
  void release() { sim_->release(); }
  void squeeze(double closure) { sim_->squeeze(closureOf(closure)); }
  double closure() const { return sim_->closure(); }

  void set(const std::string& key, const py::handle& value) {
    SimParams p = sim_->params();
    applyKey(p, key, value);
    if (auto err = validate(p, backend_name_)) raise(PyExc_ValueError, *err);
    if (p.threads != sim_->params().threads || p.simd != sim_->params().simd) {
      build(p);
    } else if (auto err = sim_->set({{key, spell(key, value)}})) { // as a script's set event
      raise(PyExc_ValueError, *err);
    }
  }

  void reset(bool animated) {
    if (animated)
      sim_->reset();
    else
      sim_->rebuild(sim_->params());
  }

  py::array_t<float> positions() {
    SimState s = state();
    return xyzArray<float>(s.pos, s.pos.size());
  }

  py::array_t<float> velocities() {
    SimState s = state();
    const float dt = sim_->lastSubstepDt();
    py::array_t<float> a({py::ssize_t(s.pos.size()), py::ssize_t(3)});
    auto m = a.mutable_unchecked<2>();
    for (size_t i = 0; i < s.pos.size(); ++i) {
      const glm::vec3 v = (glm::vec3(s.pos[i]) - glm::vec3(i < s.prev.size() ? s.prev[i] : s.pos[i])) / dt;
      for (int k = 0; k < 3; ++k) m(py::ssize_t(i), k) = v[k];
    }
    return a;
  }

  py::array_t<int32_t> triangles() {
    SimState s = state();
    return xyzArray<int32_t>(s.triangles, std::min<size_t>(s.triangle_count, s.triangles.size()));
  }

  py::object stats() {
    SimState s = state();
    SheetStats st = computeStats(s, sim_->lastSubstepDt());
    judgeIntersections(st, s);
    nlohmann::json j =
        runStatsJson(st, *backend_.solver, {sim_->params().preset, sim_->frameCount(), sim_->physicsTicks(), ms_},
                     backend_.gpu != nullptr);
    return py::module_::import("json").attr("loads")(j.dump());
  }

  std::string stateHash() { return hashHex(hashPositions(state().pos)); }

  void save(const std::string& path) {
    auto format = meshFormatFor(path);
    if (!format) raise(PyExc_ValueError, "'" + path + "': unknown extension (.ply, .glb or .gltf)");
    writeOutput(path, [&](OutputSet& outputs) -> std::optional<std::string> {
      backend_.solver->computeNormals();
      SimState s;
      backend_.solver->readback(s);
      if (*format == MeshFormat::Ply) return outputs.stage(path, [&](std::FILE* f) { return writePly(f, s); });
      MeshScene scene;
      scene.uv = sim_->topology().uv;
      auto png = textures_.find(sim_->params().preset);
      if (png == textures_.end())
        png = textures_.emplace(sim_->params().preset, receiptPng(sim_->params().preset)).first;
      scene.texture_png = png->second;
      std::string error;
      auto bytes = encodeGltf(scene, {meshFrame(s, 0.0)}, *format == MeshFormat::Glb, error);
      if (!bytes) raise(PyExc_RuntimeError, error);
      return outputs.stage(path, *bytes);
    });
  }

  bool wind() const { return sim_->wind(); }
  void setWind(const py::handle& on) { sim_->setWind(truthValue(on, "wind")); }
  bool pins() const { return sim_->pins(); }
  void setPins(const py::handle& on) { sim_->setPins(truthValue(on, "pins")); }
  bool paused() const { return sim_->paused(); }
  void setPaused(const py::handle& on) { sim_->setPaused(truthValue(on, "paused")); }
  std::string backendName() const { return backend_.solver->name(); }
  uint32_t particleCount() const { return sim_->topology().particleCount(); }
  int64_t grabbed() const { return sim_->grabbed() == SIM_NONE ? -1 : int64_t(sim_->grabbed()); }
  py::dict params() const {
    py::dict d;
    d["preset"] = sim_->params().preset;
    for (auto& [key, value] : paramValues(sim_->params())) d[py::str(key)] = value;
    return d;
  }

private:
  /// A new solver and sheet for `p` (checked); on failure the old ones stay.
  void build(const SimParams& p) {
    BackendOptions options = backendOptionsFor(backend_name_, p);
    options.device = device_;
    std::shared_ptr<gpu::VulkanContext> context;
    if (backend_name_ == "gpu") {
      context = sharedContext(options);
      options.context = context.get();
    }
    Backend backend;
    if (auto err = createBackend(options, backend)) raise(PyExc_RuntimeError, *err);
    auto sim = std::make_unique<Simulation>(p, *backend.solver);
    sim_.reset();
    backend_ = std::move(backend); // the solver stays where it is: `sim` keeps pointing at it
    context_ = std::move(context); // after the old solver is gone
    sim_ = std::move(sim);
    ms_.clear();
  }

  SimState state() {
    SimState s;
    backend_.solver->readback(s);
    return s;
  }

  std::string backend_name_;
  int device_ = -1;
  std::shared_ptr<gpu::VulkanContext> context_; // the GPU solver's (declared first: it goes last)
  Backend backend_;
  std::unique_ptr<Simulation> sim_;
  std::vector<double> ms_;
  std::map<std::string, std::string> textures_;
};

py::list devices() {
  py::list out;
#ifdef TENDER_HAS_GPU
  auto list = gpu::listDevices();
  if (!list) return out;
  for (const gpu::DeviceInfo& d : *list) {
    py::dict e;
    e["index"] = d.index;
    e["name"] = d.name;
    e["type"] = d.type;
    e["driver"] = d.driver;
    e["memory_bytes"] = d.memory_bytes;
    e["usable"] = d.usable;
    out.append(e);
  }
#endif
  return out;
}

void bindSimulation(py::module_& m) {
  py::class_<PySimulation>(m, "Simulation",
                           "A sheet on a backend: Simulation(preset='tender', backend='cpu'|'gpu', device=None, "
                           "preset_file=None, **params), params as `--set` keys with Python values; preset_file: "
                           "a preset file to start from instead of a preset (as `--preset-file`).")
      .def(py::init<const std::optional<std::string>&, const std::string&, std::optional<int>,
                    const std::optional<std::string>&, const py::kwargs&>(),
           py::arg("preset") = py::none(), py::arg("backend") = "cpu", py::arg("device") = py::none(),
           py::arg("preset_file") = py::none())
      .def("step", &PySimulation::step, py::arg("ticks") = 1, "Runs `ticks` ticks (as `tender sim --ticks`).")
      .def("grab", &PySimulation::grab, py::arg("particle"), "Grabs a particle where it is.")
      .def("grab_ray", &PySimulation::grabRay, py::arg("origin"), py::arg("direction"),
           "Grabs the nearest particle within grab_radius of the ray; returns whether one was caught.")
      .def("move", &PySimulation::move, py::arg("x"), py::arg("y"), py::arg("z"), "Moves the grab target.")
      .def("release", &PySimulation::release, "Lets go (zero or drag velocity, per the `release` key).")
      .def("squeeze", &PySimulation::squeeze, py::arg("closure"),
           "Closes the hand around the grab: 0 open .. 1 closed (a ball); release() opens it.")
      .def_property_readonly("closure", &PySimulation::closure, "The hand's closure, 0 while open or not grabbing.")
      .def("set", &PySimulation::set, py::arg("key"), py::arg("value"),
           "Sets a parameter; keys that change the sheet or the solver rebuild the sheet at rest.")
      .def("reset", &PySimulation::reset, py::arg("animated") = false,
           "Puts the sheet back at rest now, or (animated=True) over the next 30 steps.")
      .def_property_readonly("positions", &PySimulation::positions, "(N, 3) float32, a copy")
      .def_property_readonly("velocities", &PySimulation::velocities,
                             "(N, 3) float32, (pos - prev) / substep dt, a copy")
      .def_property_readonly("triangles", &PySimulation::triangles, "(T, 3) int32, the live triangles, a copy")
      .def_property("wind", &PySimulation::wind, &PySimulation::setWind, "Wind on or off (as the W key).")
      .def_property("pins", &PySimulation::pins, &PySimulation::setPins, "Pins on or off (as the P key).")
      .def_property("paused", &PySimulation::paused, &PySimulation::setPaused, "Paused steps run no physics.")
      .def_property_readonly("backend", &PySimulation::backendName)
      .def_property_readonly("particle_count", &PySimulation::particleCount)
      .def_property_readonly("grabbed", &PySimulation::grabbed, "The grabbed particle, -1 when none.")
      .def_property_readonly("params", &PySimulation::params, "Every key's value as `--set` spells it.")
      .def("stats", &PySimulation::stats, "The stats JSON of `tender sim` as a dict.")
      .def("state_hash", &PySimulation::stateHash, "FNV-1a 64 of the positions, as `tender sim` prints it.")
      .def("save", &PySimulation::save, py::arg("path"), "Writes PLY, .glb or .gltf (by extension), atomically.");
}

} // namespace
} // namespace tender

PYBIND11_MODULE(tender, m) {
  using namespace tender;
  m.doc() = "Tender: a sheet of receipt paper to grab, crumple, fold, toss and tear.\n\n"
            "Threads: every call holds the GIL from start to end, so calls from several threads on one object "
            "or on several run one at a time and are safe; they do not run in parallel.";
  // NumPy is imported here, on the importing thread: imported lazily by the first array, two
  // threads could deadlock (one holding the GIL, waiting for the other's half-done import).
  // Without NumPy the module still loads; asking for an array raises ImportError then.
  try {
    py::module_::import("numpy");
    py::detail::npy_api::get();
  } catch (const py::error_already_set&) {
  }
  py::module_::import("atexit").attr("register")(py::cpp_function([] { contextCache().clear(); }));
  m.attr("__version__") = TENDER_VERSION;
  m.def("presets", &presetNames, "The names of the built-in presets.");
  m.def("devices", &devices,
        "The Vulkan devices (dicts of index, name, type, driver, memory_bytes, usable), in the order "
        "`device=` numbers them; empty without Vulkan.");
  m.def("vulkan_built", &vulkanBuilt, "True when this build has the GPU backend.");
  m.def("param_keys", [] {
    std::vector<std::string> keys;
    for (auto& k : paramKeys()) keys.push_back(k.key);
    return keys;
  });
  bindSimulation(m);
  bindFleet(m);
}
