// Bindings of core/io/files.h: the one durable, atomic file write, which the Python side uses
// for every file it writes (aolab.files). A missing
// file becomes FileNotFoundError and a failed write OSError with its errno, so Python callers
// catch them as they would catch their own I/O errors.
#include "core/io/files.h"

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cerrno>
#include <exception>
#include <string>
#include <utility>
#include <vector>

namespace py = pybind11;

namespace aolab::python {

namespace {

// FileNotFoundError(errno, strerror-like text, filename): str() gives
// "[Errno 2] EXR file not found: '/path/scene.exr'" and `.filename` holds the path.
void raise_file_not_found(const FileNotFound& e) {
  py::object error = py::reinterpret_borrow<py::object>(PyExc_FileNotFoundError)(
      ENOENT, e.description(), e.path());
  PyErr_SetObject(PyExc_FileNotFoundError, error.ptr());
}

// OSError(errno, message): str() is "[Errno 28] cannot write ...: write failed: No space
// left on device"; the errno picks the subclass (PermissionError for EACCES).
void raise_write_failed(const WriteFailed& e) {
  py::object error = py::reinterpret_borrow<py::object>(PyExc_OSError)(e.error_number(), e.what());
  PyErr_SetObject(PyExc_OSError, error.ptr());
}

}  // namespace

void bind_files(py::module_& m) {
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const FileNotFound& e) {
      raise_file_not_found(e);
    } catch (const WriteFailed& e) {
      raise_write_failed(e);
    }
  });

  m.def(
      "write_file_durably",
      [](const std::string& path, const py::bytes& data) {
        std::string bytes = data;
        py::gil_scoped_release release;
        write_file_durably(path, bytes);
      },
      py::arg("path"), py::arg("data"),
      "Replaces `path` by `data` durably and atomically: a temporary file beside it, every\n"
      "write checked, fsync, close checked, rename, the directory synced; on any failure the\n"
      "temporary is removed, the target left as it was and OSError raised.");

  m.def(
      "write_files_durably",
      [](const std::vector<std::pair<std::string, py::bytes>>& files) {
        std::vector<std::pair<std::string, std::string>> contents;
        for (const auto& [path, data] : files) contents.emplace_back(path, std::string(data));
        py::gil_scoped_release release;
        write_files_durably(contents);
      },
      py::arg("files"),
      "Writes [(path, data), ...] that belong together: every temporary written and synced\n"
      "first, then all renamed into place.");
}

}  // namespace aolab::python
