#pragma once
/// Python values to Tender's and back, with the CLI's messages: parameters by the rule of preset
/// files (spellTyped), truth values, coordinates, output paths, arrays.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "core/output.h"
#include "core/params.h"

namespace tender {

namespace py = pybind11;

/// Raises `type` (PyExc_ValueError, PyExc_OSError...) with `message` made printable, as the
/// command line prints its errors: what a message quotes (a path, a key, a preset's name) is
/// escaped, not cut at a NUL (a C++ exception's what() would end there).
[[noreturn]] void raise(PyObject* type, const std::string& message);
/// The name of a Python value's type ("float", "NoneType").
std::string typeName(const py::handle& value);
/// A Python value spelled as `--set` takes it, by the rule of preset files (spellTyped): True/False
/// for on/off keys, int for numbers, float for numbers that are not whole, str for any key; a
/// NumPy scalar as its Python value. A type the key does not take raises TypeError, an unknown key
/// KeyError.
std::string spell(const std::string& key, const py::handle& value);
/// Applies key=value to `p`: an unknown key raises KeyError, a value of a type the key does not
/// take TypeError, a bad value ValueError (the CLI's messages).
void applyKey(SimParams& p, const std::string& key, const py::handle& value);
/// The keys of a dict of parameters: str, or TypeError naming `what`.
std::string keyOf(const py::handle& key, const std::string& what);
/// True or False (or a NumPy bool), else TypeError: None or a float is not taken as a truth value.
bool truthValue(const py::handle& value, const char* what);
/// Writes through an OutputSet (`stage` stages the file); a path that cannot be written raises
/// OSError (as open() does), an empty one ValueError.
void writeOutput(const std::string& path, const std::function<std::optional<std::string>(OutputSet&)>& stage);
/// The parameters a Simulation or a Fleet starts from: the built-in `preset` ('tender' when neither
/// is given), or the preset file `preset_file` read as `--preset-file` reads it (ValueError: an
/// unknown preset, a file that cannot be read or is malformed, or both given).
SimParams baseParams(const std::optional<std::string>& preset, const std::optional<std::string>& preset_file);
/// A point within the coordinates an input may name (ValueError naming `what` otherwise).
glm::vec3 coordinates(double x, double y, double z, const char* what);
/// A closure of the hand (0 open .. 1 closed; ValueError otherwise).
float closureOf(double closure);
/// A sequence of 3 numbers as a point (ValueError naming `what` otherwise).
glm::vec3 sequence3(const py::sequence& s, const char* what);

/// An (N, 3) array of the xyz of `v`.
template <typename T, typename V>
py::array_t<T> xyzArray(const std::vector<V>& v, size_t n) {
  py::array_t<T> a({py::ssize_t(n), py::ssize_t(3)});
  auto m = a.template mutable_unchecked<2>();
  for (size_t i = 0; i < n; ++i)
    for (py::ssize_t k = 0; k < 3; ++k) m(py::ssize_t(i), k) = T(v[i][int(k)]);
  return a;
}

} // namespace tender
