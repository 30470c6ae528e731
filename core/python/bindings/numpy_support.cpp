#include "core/python/bindings/numpy_support.h"

#include <memory>

#include "core/base/check.h"

namespace aolab::python {

std::string shape_string(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) {
    if (i) s += ", ";  // appended apart: GCC 12 misreads `const char* + string` under LTO
    s += std::to_string(a.shape(i));
  }
  return s + (a.ndim() == 1 ? ",)" : ")");
}

FloatArray real_array(const py::object& value, const std::string& name,
                      const std::string& expected) {
  if (value.is_none()) throw_invalid(name, "must be " + expected, "None");
  py::array array;
  try {
    array = py::module_::import("numpy").attr("asarray")(value);
  } catch (py::error_already_set& e) {
    if (!e.matches(PyExc_ValueError) && !e.matches(PyExc_TypeError)) throw;
    throw_invalid(name, "must be " + expected,
                  std::string(py::str(py::type::of(value).attr("__name__"))) + " (" +
                      py::str(e.value()).cast<std::string>() + ")");
  }
  const char kind = array.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u')
    throw_invalid(name, "must be " + expected + " of real numbers (an integer or floating dtype)",
                  "dtype " + py::str(array.dtype()).cast<std::string>());
  return FloatArray::ensure(array);
}

ConstImageView view_of(const FloatArray& a, const std::string& name, int channels,
                       int alt_channels) {
  // An empty array is named by its shape as the caller wrote it: "(0, 5)", not "5x0".
  if (a.ndim() >= 2 && (a.shape(0) == 0 || a.shape(1) == 0))
    throw_invalid(name, "must not be empty (height and width >= 1)", shape_string(a));
  if (channels == 0) {
    if (a.ndim() != 2) throw_invalid(name, "must be a 2-D array (H, W)", shape_string(a));
    return {a.data(), int(a.shape(1)), int(a.shape(0)), 1};
  }
  const bool ok_channels =
      a.ndim() == 3 && (a.shape(2) == channels || (alt_channels > 0 && a.shape(2) == alt_channels));
  if (!ok_channels) {
    const std::string want = alt_channels > 0
                                 ? std::to_string(channels) + "|" + std::to_string(alt_channels)
                                 : std::to_string(channels);
    throw_invalid(name, "must be a 3-D array (H, W, " + want + ")", shape_string(a));
  }
  return {a.data(), int(a.shape(1)), int(a.shape(0)), int(a.shape(2))};
}

py::array_t<float> to_numpy(Image&& image) {
  auto* owner = new Image(std::move(image));
  py::capsule free_when_done(owner, [](void* p) { delete static_cast<Image*>(p); });
  const py::ssize_t h = owner->height(), w = owner->width(), c = owner->channels();
  if (c == 1) return py::array_t<float>({h, w}, owner->data(), free_when_done);
  return py::array_t<float>({h, w, c}, owner->data(), free_when_done);
}

}  // namespace aolab::python
