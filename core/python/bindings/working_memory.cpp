// The working-memory cache (core/base/working_memory.h): how much it holds, its limit, and
// releasing it.
#include "core/base/working_memory.h"

#include <cstdint>
#include <string>

#include "core/base/check.h"
#include "core/python/bindings/numpy_support.h"

namespace aolab::python {

namespace {

// A limit from Python: an int (or a numpy integer) >= 0 that fits 64 bits; anything else is
// refused naming limit_bytes and the value as Python shows it, with its type.
std::int64_t limit_from_python(const py::handle& value) {
  const char* requirement = "must be a whole number of bytes >= 0 (0 = cache nothing)";
  const std::string shown = py::repr(value).cast<std::string>() + " (" +
                            py::type::of(value).attr("__name__").cast<std::string>() + ")";
  const bool is_bool = py::isinstance<py::bool_>(value) ||
                       py::isinstance(value, py::module_::import("numpy").attr("bool_"));
  if (is_bool || !PyIndex_Check(value.ptr())) throw_invalid("limit_bytes", requirement, shown);
  const py::int_ whole = py::reinterpret_steal<py::int_>(PyNumber_Index(value.ptr()));
  if (!whole) throw py::error_already_set();
  int overflow = 0;
  const long long v = PyLong_AsLongLongAndOverflow(whole.ptr(), &overflow);
  if (overflow > 0) throw_invalid("limit_bytes", "must be below 2^63 bytes", shown);
  if (overflow < 0 || v < 0) throw_invalid("limit_bytes", requirement, shown);
  return v;
}

}  // namespace

void bind_working_memory(py::module_& m) {
  m.def(
      "working_memory",
      [] {
        const WorkingMemoryStats s = working_memory_stats();
        py::dict d;
        d["cached_bytes"] = s.cached_bytes;
        d["cached_blocks"] = s.cached_blocks;
        d["in_use_bytes"] = s.in_use_bytes;
        d["limit_bytes"] = s.limit_bytes;
        return d;
      },
      "The working-memory cache: cached_bytes (idle, kept for the next computation), "
      "cached_blocks, in_use_bytes (large working arrays alive now, results included) and "
      "limit_bytes (the cap on cached_bytes).");
  m.def(
      "set_working_memory_limit",
      [](const py::object& limit_bytes) {
        const std::int64_t limit = limit_from_python(limit_bytes);
        py::gil_scoped_release release;
        set_working_memory_limit(limit);
      },
      py::arg("limit_bytes"),
      "Caps the bytes the cache keeps idle (0 = keep nothing), evicting the least recently "
      "used blocks down to it; ValueError naming limit_bytes for anything but a whole number "
      ">= 0.");
  m.def(
      "release_working_memory",
      [] {
        py::gil_scoped_release release;
        release_working_memory();
      },
      "Frees every block the cache keeps idle (the limit stays).");
}

}  // namespace aolab::python
