// Python <-> C++ for the isolink module: JSON to dicts and lists, waveforms to numpy arrays, spec
// arguments (a path, or a dict with the YAML file's structure) to what the library's readers
// take, and Status errors to isolink.Error.
//
//   SpecArg a = spec_arg(obj, "spec");   // a file, or config::key_path_document text
//   StatusOr<link::LinkSpec> s = a.is_file() ? read_link_spec_file(a.path)
//                                            : read_link_spec_text(a.text, a.name);
//   py::dict d = to_python(reports::run_report_json(...));
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "base/status.h"
#include "base/waveform.h"

namespace isolink::python {

namespace py = pybind11;

// isolink.Error, set once when the module is created.
void set_error_type(PyObject* type);
// Raises isolink.Error with the status's message (the CLI's text).
[[noreturn]] void raise(const Status& s);
template <typename T>
T take(StatusOr<T> v) {
  if (!v) raise(v.status());
  return std::move(*v);
}

py::object to_python(const nlohmann::ordered_json& j);
py::array_t<double> to_numpy(const std::vector<double>& v);
// {"time": array, "<probe>": array, ...} (seconds, volts, amperes).
py::dict wave_dict(const Waveform& w);

// A spec argument: a file (str or os.PathLike) or a document built in memory from a dict
// (config::key_path_document: its errors name key paths, "cable.lenght: error: ...", and the
// whole dict by `name`). Relative paths inside a dict (a sweep's base, a pack's hop files) are
// taken from the current working directory.
struct SpecArg {
  std::string path;  // the file, when given one
  std::string text;  // the dict as JSON text, when given a dict
  std::string name;  // the argument's name ("spec", "sweep", "pack_spec")
  bool is_file() const { return text.empty(); }
  // The file, or the name standing for the dict: the context of errors from the analysis.
  const std::string& where() const { return is_file() ? path : name; }
};
// name is the argument's name, for messages. Anything but a path or a dict raises isolink.Error.
SpecArg spec_arg(const py::handle& obj, const std::string& name);

// A dict, list or value as JSON; key_path names it in errors ("cable.length"). Keys must be
// strings; numbers must be finite; values are str, int, float, bool or None (numpy scalars too).
nlohmann::ordered_json to_json(const py::handle& obj, const std::string& key_path);

// A time argument in seconds: a positive number, or SPICE text ("10n", "1.5u"); None stays
// empty. name names it in errors.
std::optional<double> time_arg(const py::handle& obj, const std::string& name);

// Solver warnings (floating nodes, ...), each once, as Python UserWarnings: what the CLI prints
// on stderr.
void warn_once(const std::vector<std::string>& warnings);

}  // namespace isolink::python
