// tender.Fleet: sheets of one grid that tick as one batch (core/fleet.h), from Python.
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "core/fleet.h"
#include "core/params.h"
#include "core/script.h"
#include "core/stats.h"
#include "python/convert.h"
#include "python/module.h"
#ifdef TENDER_HAS_GPU
#include "gpu/context.h"
#endif

namespace py = pybind11;

namespace tender {
namespace {

/// A fleet: B sheets of one grid ticking as one batch (core/fleet.h), each with its own parameters
/// and optional script. Sheet i gives the same state as tender.Simulation of its parameters.
class PyFleet {
public:
  PyFleet(const py::object& sheets, const std::optional<std::string>& preset, const std::string& backend,
          std::optional<int> device, const std::optional<std::vector<std::string>>& scripts,
          const std::optional<std::string>& preset_file, const py::kwargs& params) {
    SimParams base = baseParams(preset, preset_file);
    for (auto item : params) applyKey(base, keyOf(item.first, "params"), item.second);
    if (backend != "cpu" && backend != "gpu") raise(PyExc_ValueError, "unknown backend '" + backend + "' (cpu or gpu)");
    if (device && *device < 0) raise(PyExc_ValueError, "device: expected an index >= 0 (see tender.devices())");
    // sheets: a count of sheets of the common parameters, or one dict of keys per sheet over them
    std::vector<FleetSheet> list;
    if (py::isinstance<py::bool_>(sheets)) {
      raise(PyExc_TypeError, "sheets: expected a count or a list of dicts, got bool");
    } else if (py::isinstance<py::int_>(sheets)) {
      // Compared as Python ints: any size is refused in words, never by a failed conversion.
      if (sheets < py::int_(1) || sheets > py::int_(kMaxBatchSheets))
        raise(PyExc_ValueError, "sheets: expected 1 to " + std::to_string(kMaxBatchSheets) + ", got " +
                                    py::str(sheets).cast<std::string>());
      list.assign(sheets.cast<size_t>(), FleetSheet{base, {}});
    } else if (py::isinstance<py::sequence>(sheets) && !py::isinstance<py::str>(sheets)) {
      size_t i = 0;
      for (const py::handle& item : sheets) {
        const std::string where = "sheets[" + std::to_string(i++) + "]";
        if (!py::isinstance<py::dict>(item)) raise(PyExc_TypeError, where + ": expected a dict, got " + typeName(item));
        if (i > kMaxBatchSheets) break;
        FleetSheet s{base, {}};
        for (auto kv : item.cast<py::dict>()) applyKey(s.params, keyOf(kv.first, where), kv.second);
        list.push_back(std::move(s));
      }
      if (list.empty() || py::len(sheets) > kMaxBatchSheets)
        raise(PyExc_ValueError, "sheets: expected 1 to " + std::to_string(kMaxBatchSheets) + " sheets, got " +
                                    std::to_string(py::len(sheets)));
    } else {
      raise(PyExc_TypeError, "sheets: expected a count or a list of dicts, got " + typeName(sheets));
    }
    if (scripts) {
      if (scripts->size() != list.size())
        raise(PyExc_ValueError, "scripts: expected one per sheet (" + std::to_string(list.size()) + "), got " +
                                    std::to_string(scripts->size()));
      for (size_t i = 0; i < list.size(); ++i) {
        std::string error;
        auto script = parseScript(scripts->at(i), error);
        if (!script) raise(PyExc_ValueError, "scripts[" + std::to_string(i) + "]: " + error);
        if (auto err = checkScript(*script, list[i].params, backend, true))
          raise(PyExc_ValueError, "scripts[" + std::to_string(i) + "]: " + *err);
        list[i].script = std::move(*script);
      }
    }
    for (size_t i = 0; i < list.size(); ++i) {
      if (auto err = validate(list[i].params, backend))
        raise(PyExc_ValueError, "sheet " + std::to_string(i) + ": " + *err);
      if (auto err = batchMismatch(list[0].params, list[i].params))
        raise(PyExc_ValueError, "sheet " + std::to_string(i) + ": " + *err);
    }
    // The whole batch must fit this machine's memory (and a GPU's), refused before anything is allocated.
    if (auto err = batchMemoryError(list[0].params, backend, list.size(), device.value_or(-1)))
      raise(PyExc_ValueError, *err);
    BackendOptions options = backendOptionsFor(backend, list[0].params);
    options.device = device.value_or(-1);
    if (backend == "gpu") {
      context_ = sharedContext(options);
      options.context = context_.get();
    }
    if (auto err = createBatch(options, uint32_t(list.size()), batch_)) raise(PyExc_RuntimeError, *err);
    fleet_ = std::make_unique<Fleet>(*batch_, list);
  }

  void step(int64_t ticks) {
    if (ticks < 0) raise(PyExc_ValueError, "ticks: expected a count >= 0, got " + std::to_string(ticks));
    for (int64_t t = 0; t < ticks; ++t) {
      auto t0 = std::chrono::steady_clock::now();
      fleet_->tick();
      batch_->finish();
      ms_.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      if ((t & 15) == 15 && PyErr_CheckSignals() != 0) throw py::error_already_set();
    }
  }

  /// (B, N, 3) float32 of every sheet's positions, or of (pos - prev) / substep dt (one read-back).
  py::array_t<float> positions(bool velocities) {
    const size_t b = fleet_->size(), n = fleet_->sim(0).topology().particleCount();
    std::vector<glm::vec4> pos, prev;
    batch_->readPositions(pos, prev);
    py::array_t<float> a({py::ssize_t(b), py::ssize_t(n), py::ssize_t(3)});
    auto m = a.mutable_unchecked<3>();
    for (size_t i = 0; i < b; ++i) {
      const float dt = fleet_->sim(uint32_t(i)).lastSubstepDt();
      for (size_t j = 0; j < n; ++j) {
        const glm::vec3 p(pos[i * n + j]), q(prev[i * n + j]);
        const glm::vec3 v = velocities ? (p - q) / dt : p;
        for (int k = 0; k < 3; ++k) m(py::ssize_t(i), py::ssize_t(j), k) = v[k];
      }
    }
    return a;
  }

  py::object stats(std::optional<int64_t> sheet) {
    if (!sheet) {
      py::list out;
      for (uint32_t i = 0; i < fleet_->size(); ++i) out.append(stats(i));
      return out;
    }
    Simulation& sim = at(*sheet);
    SimState s = state(uint32_t(*sheet));
    SheetStats st = computeStats(s, sim.lastSubstepDt());
    judgeIntersections(st, s);
    nlohmann::json j = runStatsJson(st, sim.solver(), {sim.params().preset, sim.frameCount(), sim.physicsTicks(), ms_},
                                    batch_->name() == "gpu");
    return py::module_::import("json").attr("loads")(j.dump());
  }

  std::vector<std::string> stateHashes() {
    const size_t n = fleet_->sim(0).topology().particleCount();
    std::vector<glm::vec4> pos, prev;
    batch_->readPositions(pos, prev);
    std::vector<std::string> out;
    for (size_t i = 0; i < fleet_->size(); ++i)
      out.push_back(hashHex(hashPositions(std::vector<glm::vec4>(pos.begin() + i * n, pos.begin() + (i + 1) * n))));
    return out;
  }

  void grab(int64_t sheet, int64_t particle) {
    Simulation& sim = at(sheet);
    const uint32_t n = sim.topology().particleCount();
    if (particle < 0 || particle >= int64_t(n))
      raise(PyExc_ValueError,
            "particle " + std::to_string(particle) + " does not exist (the sheet has " + std::to_string(n) + ")");
    sim.grabParticle(uint32_t(particle));
  }
  void move(int64_t sheet, double x, double y, double z) { at(sheet).moveGrab(coordinates(x, y, z, "move")); }
  void release(int64_t sheet) { at(sheet).release(); }
  void squeeze(int64_t sheet, double closure) { at(sheet).squeeze(closureOf(closure)); }
  uint32_t size() const { return fleet_->size(); }
  std::string backendName() const { return batch_->name(); }
  py::dict params(int64_t sheet) {
    py::dict d;
    d["preset"] = at(sheet).params().preset;
    for (auto& [key, value] : paramValues(at(sheet).params())) d[py::str(key)] = value;
    return d;
  }

private:
  Simulation& at(int64_t sheet) const {
    if (sheet < 0 || sheet >= int64_t(fleet_->size()))
      throw py::index_error("sheet " + std::to_string(sheet) + " does not exist (the fleet has " +
                            std::to_string(fleet_->size()) + ")");
    return fleet_->sim(uint32_t(sheet));
  }
  SimState state(uint32_t i) {
    SimState s;
    fleet_->sim(i).solver().readback(s);
    return s;
  }

  std::shared_ptr<gpu::VulkanContext> context_; // the GPU batch's (declared first: it goes last)
  std::unique_ptr<SheetBatch> batch_;
  std::unique_ptr<Fleet> fleet_;
  std::vector<double> ms_;
};

} // namespace

void bindFleet(py::module_& m) {
  py::class_<PyFleet>(m, "Fleet",
                      "Sheets of one grid that tick as one batch: Fleet(sheets=N or [dict per sheet], "
                      "preset='tender', backend='cpu'|'gpu', device=None, scripts=None, preset_file=None, "
                      "**params). Each dict overrides the common params for its sheet (any key but the grid's); "
                      "scripts: one input script text per sheet; preset_file: a preset file to start from instead "
                      "of a preset. Sheet i ends where tender.Simulation of its params ends.")
      .def(py::init<const py::object&, const std::optional<std::string>&, const std::string&, std::optional<int>,
                    const std::optional<std::vector<std::string>>&, const std::optional<std::string>&,
                    const py::kwargs&>(),
           py::arg("sheets"), py::arg("preset") = py::none(), py::arg("backend") = "cpu",
           py::arg("device") = py::none(), py::arg("scripts") = py::none(), py::arg("preset_file") = py::none())
      .def("step", &PyFleet::step, py::arg("ticks") = 1, "Runs `ticks` steps of every sheet, each as one batch.")
      .def_property_readonly(
          "positions", [](PyFleet& f) { return f.positions(false); }, "(B, N, 3) float32, a copy")
      .def_property_readonly(
          "velocities", [](PyFleet& f) { return f.positions(true); }, "(B, N, 3) float32, (pos - prev) / substep dt")
      .def("stats", &PyFleet::stats, py::arg("sheet") = py::none(),
           "The stats JSON of `tender sim` of one sheet as a dict, or a list of every sheet's.")
      .def("state_hashes", &PyFleet::stateHashes, "Every sheet's state hash, as `tender sim` prints it.")
      .def("grab", &PyFleet::grab, py::arg("sheet"), py::arg("particle"), "Grabs a particle of a sheet where it is.")
      .def("move", &PyFleet::move, py::arg("sheet"), py::arg("x"), py::arg("y"), py::arg("z"),
           "Moves a sheet's grab target.")
      .def("release", &PyFleet::release, py::arg("sheet"), "Lets go of a sheet's particle.")
      .def("squeeze", &PyFleet::squeeze, py::arg("sheet"), py::arg("closure"),
           "Closes the hand around a sheet's grab: 0 open .. 1 closed.")
      .def("params", &PyFleet::params, py::arg("sheet"), "Every key's value of a sheet as `--set` spells it.")
      .def("__len__", &PyFleet::size)
      .def_property_readonly("backend", &PyFleet::backendName);
}

} // namespace tender
