#include "core/python/bindings/numpy_support.h"

#include <memory>

#include "core/base/check.h"

namespace aolab::python {

namespace {
std::string shape_string(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) {
    if (i) s += ", ";  // appended apart: GCC 12 misreads `const char* + string` under LTO
    s += std::to_string(a.shape(i));
  }
  return s + (a.ndim() == 1 ? ",)" : ")");
}
}  // namespace

ConstImageView view_of(const FloatArray& a, const std::string& name, int channels,
                       int alt_channels) {
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
