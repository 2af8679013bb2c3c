#include "python/convert.h"

#include <cmath>

#include "core/script.h"
#include "core/text.h"

namespace tender {

void raise(PyObject* type, const std::string& message) {
  PyErr_SetString(type, printable(message).c_str());
  throw py::error_already_set();
}

std::string typeName(const py::handle& value) {
  return py::str(py::type::of(value).attr("__name__")).cast<std::string>();
}

std::string spell(const std::string& key, const py::handle& value) {
  std::optional<std::string> err;
  std::string out;
  if (py::isinstance<py::bool_>(value)) {
    err = spellTyped(key, ValueType::Bool, value.cast<bool>() ? "true" : "false", out);
  } else if (py::isinstance<py::int_>(value)) {
    err = spellTyped(key, ValueType::Whole, py::str(value).cast<std::string>(), out);
  } else if (py::isinstance<py::float_>(value)) {
    err = spellTyped(key, ValueType::Number, py::repr(value).cast<std::string>(), out);
  } else if (py::isinstance<py::str>(value)) {
    err = spellTyped(key, ValueType::Text, value.cast<std::string>(), out);
  } else if (py::hasattr(value, "item") && py::hasattr(value, "dtype")) {
    py::object item = value.attr("item")();
    if (py::isinstance<py::bool_>(item) || py::isinstance<py::int_>(item) || py::isinstance<py::float_>(item))
      return spell(key, item);
    err = key + ": expected a bool, an int, a float or a str, got " + typeName(value);
  } else {
    err = key + ": expected a bool, an int, a float or a str, got " + typeName(value);
  }
  if (!err) return out;
  if (!paramInfo(key)) raise(PyExc_KeyError, *err);
  raise(PyExc_TypeError, *err);
}

void applyKey(SimParams& p, const std::string& key, const py::handle& value) {
  const std::string assignment = key + "=" + spell(key, value);
  auto err = applyOverride(p, assignment);
  if (!err) return;
  if (key.empty() || !paramInfo(key)) raise(PyExc_KeyError, *err);
  raise(PyExc_ValueError, *err);
}

std::string keyOf(const py::handle& key, const std::string& what) {
  if (!py::isinstance<py::str>(key))
    raise(PyExc_TypeError, what + ": keys are parameter names (str), got " + typeName(key));
  return key.cast<std::string>();
}

bool truthValue(const py::handle& value, const char* what) {
  if (py::isinstance<py::bool_>(value)) return value.cast<bool>();
  if (py::hasattr(value, "dtype") && py::hasattr(value, "item")) {
    py::object item = value.attr("item")();
    if (py::isinstance<py::bool_>(item)) return item.cast<bool>();
  }
  raise(PyExc_TypeError, std::string(what) + ": expected True or False, got " + typeName(value));
}

void writeOutput(const std::string& path, const std::function<std::optional<std::string>(OutputSet&)>& stage) {
  if (path.empty()) raise(PyExc_ValueError, "an output path is empty");
  OutputSet outputs;
  std::optional<std::string> err = outputs.add(path);
  if (!err) err = stage(outputs);
  if (!err) err = outputs.commit();
  if (err) {
    raise(PyExc_OSError, *err);
  }
}

SimParams baseParams(const std::optional<std::string>& preset, const std::optional<std::string>& preset_file) {
  if (preset && preset_file) raise(PyExc_ValueError, "preset and preset_file: give one, not both");
  SimParams p;
  if (preset_file) {
    if (auto err = loadPresetFile(*preset_file, p)) raise(PyExc_ValueError, "preset_file: " + *err);
    return p;
  }
  const std::string name = preset.value_or("tender");
  auto q = presetParams(name);
  if (!q) raise(PyExc_ValueError, unknownPreset(name));
  return *q;
}

glm::vec3 coordinates(double x, double y, double z, const char* what) {
  const double v[3] = {x, y, z};
  for (double d : v)
    if (!(std::fabs(d) <= double(kMaxCoordinate)))
      raise(PyExc_ValueError, std::string(what) + ": " + std::to_string(d) + " is out of range [-" +
                                  std::to_string(int64_t(kMaxCoordinate)) + ", " +
                                  std::to_string(int64_t(kMaxCoordinate)) + "]");
  return {float(x), float(y), float(z)};
}

float closureOf(double closure) {
  if (auto err = checkClosure(closure)) raise(PyExc_ValueError, "squeeze: " + *err);
  return float(closure);
}

glm::vec3 sequence3(const py::sequence& s, const char* what) {
  if (py::len(s) != 3) raise(PyExc_ValueError, std::string(what) + ": expected 3 numbers");
  double v[3];
  for (size_t k = 0; k < 3; ++k) {
    try {
      v[k] = s[k].cast<double>();
    } catch (const py::cast_error&) {
      raise(PyExc_ValueError, std::string(what) + ": expected 3 numbers");
    }
  }
  return coordinates(v[0], v[1], v[2], what);
}

} // namespace tender
