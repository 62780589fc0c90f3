#include "python/convert.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "base/si_number.h"
#include "config/key_path.h"

namespace isolink::python {

namespace {
PyObject* g_error = nullptr;  // isolink.Error

[[noreturn]] void raise_at(const std::string& where, const std::string& message) {
  raise(Status::Error(fmt::format("{}: error: {}", where, message)));
}

std::string type_name(const py::handle& obj) {
  return py::str(py::type::handle_of(obj).attr("__name__")).cast<std::string>();
}
}  // namespace

void set_error_type(PyObject* type) {
  g_error = type;
}

void raise(const Status& s) {
  PyErr_SetString(g_error, s.message().c_str());
  throw py::error_already_set();
}

py::object to_python(const nlohmann::ordered_json& j) {
  using T = nlohmann::ordered_json::value_t;
  switch (j.type()) {
    case T::null:
      return py::none();
    case T::boolean:
      return py::bool_(j.get<bool>());
    case T::number_integer:
      return py::int_(j.get<int64_t>());
    case T::number_unsigned:
      return py::int_(j.get<uint64_t>());
    case T::number_float:
      return py::float_(j.get<double>());
    case T::string:
      return py::str(j.get_ref<const std::string&>());
    case T::array: {
      py::list l;
      for (const auto& e : j) l.append(to_python(e));
      return l;
    }
    case T::object: {
      py::dict d;
      for (const auto& [k, v] : j.items()) d[py::str(k)] = to_python(v);
      return d;
    }
    default:
      return py::none();  // binary / discarded: never produced by isolink's writers
  }
}

py::array_t<double> to_numpy(const std::vector<double>& v) {
  return py::array_t<double>(static_cast<py::ssize_t>(v.size()), v.data());
}

py::dict wave_dict(const Waveform& w) {
  py::dict d;
  d["time"] = to_numpy(w.time);
  for (size_t k = 0; k < w.names.size(); ++k) d[py::str(w.names[k])] = to_numpy(w.columns[k]);
  return d;
}

nlohmann::ordered_json to_json(const py::handle& obj, const std::string& key_path) {
  if (obj.is_none()) return nullptr;
  if (py::isinstance<py::bool_>(obj)) return obj.cast<bool>();
  if (py::isinstance<py::str>(obj)) return obj.cast<std::string>();
  if (py::isinstance<py::dict>(obj)) {
    nlohmann::ordered_json out = nlohmann::ordered_json::object();
    for (const auto& [k, v] : obj.cast<py::dict>()) {
      if (!py::isinstance<py::str>(k))
        raise_at(key_path.empty() ? "(top level)" : key_path,
                 fmt::format("a key must be a str, got {} {}", type_name(k),
                             py::repr(k).cast<std::string>()));
      const std::string key = k.cast<std::string>();
      out[key] = to_json(v, key_path.empty() ? key : key_path + "." + key);
    }
    return out;
  }
  if (py::isinstance<py::list>(obj) || py::isinstance<py::tuple>(obj)) {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    size_t i = 0;
    for (const py::handle item : obj)
      out.push_back(to_json(item, fmt::format("{}[{}]", key_path, i++)));
    return out;
  }
  // int before float: 12 stays "12". numpy integers have __index__, numpy floats __float__.
  if (py::isinstance<py::int_>(obj) || py::hasattr(obj, "__index__"))
    return py::int_(py::reinterpret_borrow<py::object>(obj)).cast<int64_t>();
  if (py::isinstance<py::float_>(obj) || py::hasattr(obj, "__float__")) {
    const double v = py::float_(py::reinterpret_borrow<py::object>(obj)).cast<double>();
    if (!std::isfinite(v)) raise_at(key_path, fmt::format("{} is not a finite number", v));
    return v;
  }
  raise_at(key_path, fmt::format("a {} cannot be a spec value (give str, int, float, bool, None, "
                                 "a list or a dict)",
                                 type_name(obj)));
}

SpecArg spec_arg(const py::handle& obj, const std::string& name) {
  SpecArg a;
  a.name = name;
  if (py::isinstance<py::dict>(obj)) {
    a.text = config::key_path_document(to_json(obj, "").dump(1));
    return a;
  }
  if (py::isinstance<py::str>(obj) || py::hasattr(obj, "__fspath__")) {
    a.path = py::str(py::module_::import("os").attr("fspath")(obj)).cast<std::string>();
    if (a.path.empty()) raise_at(name, "an empty path");
    return a;
  }
  raise_at(name,
           fmt::format("expected a path (str or os.PathLike) or a dict, got {}", type_name(obj)));
}

std::optional<double> time_arg(const py::handle& obj, const std::string& name) {
  if (obj.is_none()) return std::nullopt;
  double v = 0;
  if (py::isinstance<py::str>(obj)) {
    const std::string text = obj.cast<std::string>();
    if (!parse_si_number(text, v))
      raise_at(name, fmt::format("expects a positive time such as 10n or 1e-8, got '{}'", text));
  } else if (!py::isinstance<py::bool_>(obj) &&
             (py::isinstance<py::float_>(obj) || py::isinstance<py::int_>(obj) ||
              py::hasattr(obj, "__float__"))) {
    v = py::float_(py::reinterpret_borrow<py::object>(obj)).cast<double>();
  } else {
    raise_at(name, fmt::format("expects a time in seconds (a number or SPICE text such as "
                               "'10n'), got {}",
                               type_name(obj)));
  }
  if (!(v > 0) || !std::isfinite(v))
    raise_at(name, fmt::format("must be a positive, finite time, got {:g}", v));
  return v;
}

void warn_once(const std::vector<std::string>& warnings) {
  std::vector<std::string> seen;
  for (const std::string& w : warnings) {
    if (std::find(seen.begin(), seen.end(), w) != seen.end()) continue;
    seen.push_back(w);
    if (PyErr_WarnEx(PyExc_UserWarning, w.c_str(), 2) < 0) throw py::error_already_set();
  }
}

}  // namespace isolink::python
