#include "evfs/python/reconstruct_options.h"

#include <Python.h>

#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "evfs/core/error.h"

namespace evfs {
namespace {

namespace py = pybind11;

[[noreturn]] void WrongType(const std::string& key, const char* expected, py::handle value) {
  throw InvalidArgumentError("option '" + key + "' must be " + expected + ", not " +
                             std::string(py::str(py::type::handle_of(value).attr("__name__"))));
}

// Python bools are ints: numbers and counts refuse them explicitly.
bool IsBool(py::handle value) { return PyBool_Check(value.ptr()) != 0; }

double ToDouble(const std::string& key, py::handle value) {
  if (IsBool(value) || PyNumber_Check(value.ptr()) == 0 || PyUnicode_Check(value.ptr()) != 0) {
    WrongType(key, "a number", value);
  }
  return py::cast<double>(value);
}

int64_t ToInteger(const std::string& key, py::handle value, int64_t min, int64_t max) {
  if (IsBool(value) || PyIndex_Check(value.ptr()) == 0) WrongType(key, "an integer", value);
  const py::int_ integer = py::reinterpret_steal<py::int_>(PyNumber_Index(value.ptr()));
  int overflow = 0;
  const long long result = PyLong_AsLongLongAndOverflow(integer.ptr(), &overflow);
  if (overflow != 0 || result < min || result > max) {
    throw InvalidArgumentError("option '" + key + "' must be between " + std::to_string(min) +
                               " and " + std::to_string(max));
  }
  return result;
}

std::string ToString(const std::string& key, py::handle value) {
  if (PyUnicode_Check(value.ptr()) == 0) WrongType(key, "a string", value);
  return py::cast<std::string>(value);
}

// A sequence of numbers as the command line's comma-separated text, each number written with
// the digits that read back as the same double.
std::string ToNumberList(const std::string& key, py::handle value) {
  if (PyUnicode_Check(value.ptr()) != 0 || PySequence_Check(value.ptr()) == 0) {
    WrongType(key, "a sequence of numbers", value);
  }
  std::string list;
  for (const py::handle item : value) {
    char text[64];
    std::snprintf(text, sizeof(text), "%.17g", ToDouble(key, item));
    list += (list.empty() ? "" : ",") + std::string(text);
  }
  return list;
}

// `value` as the type of `option`'s default.
OptionValue ToOptionValue(const OptionDefinition& option, py::handle value) {
  const std::string& key = option.name;
  switch (option.default_value.index()) {
    case 0:
      if (!IsBool(value)) WrongType(key, "True or False", value);
      return value.ptr() == Py_True;
    case 1:
      return static_cast<int32_t>(ToInteger(key, value, std::numeric_limits<int32_t>::min(),
                                            std::numeric_limits<int32_t>::max()));
    case 2:
      return ToInteger(key, value, std::numeric_limits<int64_t>::min(),
                       std::numeric_limits<int64_t>::max());
    case 3:
      return static_cast<uint64_t>(ToInteger(key, value, 0, std::numeric_limits<int64_t>::max()));
    case 4:
      return ToDouble(key, value);
    default:
      return (option.uses & kNumberList) ? ToNumberList(key, value) : ToString(key, value);
  }
}

py::object ToPython(const OptionDefinition& option, const OptionValue& value) {
  if (option.uses & kNumberList) {
    return py::cast(ParseNumberList(std::get<std::string>(value), "--" + option.name));
  }
  return std::visit([](const auto& v) { return py::object(py::cast(v)); }, value);
}

}  // namespace

void ApplyPythonOptions(const py::handle& options, unsigned key_use, OptionValues* values) {
  if (options.is_none()) return;
  if (!py::isinstance<py::dict>(options)) {
    throw InvalidArgumentError("options must be a dict of flag names and values, not " +
                               std::string(py::str(py::type::handle_of(options).attr("__name__"))));
  }
  for (const auto& [key_object, value] : py::reinterpret_borrow<py::dict>(options)) {
    const std::string key = py::str(key_object);
    const OptionDefinition* option = FindEvfsOption(key);
    if (option == nullptr || !(option->uses & key_use)) {
      std::string known;
      for (const OptionDefinition& candidate : EvfsOptions()) {
        if (candidate.uses & key_use) known += (known.empty() ? "" : ", ") + candidate.name;
      }
      throw InvalidArgumentError("unknown option '" + key + "': expected one of " + known);
    }
    values->Set(key, ToOptionValue(*option, value));
  }
}

py::dict PythonOptionDefaults(unsigned key_use) {
  py::dict defaults;
  for (const OptionDefinition& option : EvfsOptions()) {
    if (option.uses & key_use) {
      defaults[option.name.c_str()] = ToPython(option, option.default_value);
    }
  }
  return defaults;
}

}  // namespace evfs
