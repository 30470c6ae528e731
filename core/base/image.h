// Image types: a non-owning strided view and an owning image, float pixels, row 0 at the top.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/base/check.h"
#include "core/base/working_memory.h"

namespace aolab {

/// A view of `channels` interleaved floats per pixel, rows top to bottom, `row_stride` floats
/// between rows. It never owns memory: numpy arrays and Image both hand out views, which is
/// how arrays pass between Python and the core without copies.
template <class T>
struct ImageView {
  T* data = nullptr;
  int width = 0;
  int height = 0;
  int channels = 1;
  std::ptrdiff_t row_stride = 0;  ///< in elements; width * channels when contiguous

  ImageView() = default;
  ImageView(T* data_, int width_, int height_, int channels_ = 1, std::ptrdiff_t row_stride_ = 0)
      : data(data_),
        width(width_),
        height(height_),
        channels(channels_),
        row_stride(row_stride_ ? row_stride_ : std::ptrdiff_t(width_) * channels_) {}
  /// A read-only view of a writable one.
  template <class U>
  ImageView(const ImageView<U>& o)  // NOLINT(google-explicit-constructor)
      : data(o.data),
        width(o.width),
        height(o.height),
        channels(o.channels),
        row_stride(o.row_stride) {}

  bool empty() const { return data == nullptr || width <= 0 || height <= 0; }
  std::size_t pixel_count() const { return std::size_t(width) * std::size_t(height); }
  T* row(int y) const { return data + std::ptrdiff_t(y) * row_stride; }
  T& operator()(int x, int y, int c = 0) const {
    DCHECK_LT(x, width);
    DCHECK_LT(y, height);
    DCHECK_LT(c, channels);
    return data[std::ptrdiff_t(y) * row_stride + std::ptrdiff_t(x) * channels + c];
  }
};

using ConstImageView = ImageView<const float>;
using MutableImageView = ImageView<float>;

/// An owning, contiguous float image. Its pixels come from the working-memory cache
/// (working_memory.h): an output or intermediate image of one frame reuses the memory of the
/// last, instead of fresh pages from the system every frame.
class Image {
 public:
  Image() = default;
  Image(int width, int height, int channels = 1, float fill = 0.0f)
      : width_(width),
        height_(height),
        channels_(channels),
        pixels_(std::size_t(width) * std::size_t(height) * std::size_t(channels), fill) {
    CHECK_GE(width, 0);
    CHECK_GE(height, 0);
    CHECK_GE(channels, 1);
  }

  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  float* data() { return pixels_.data(); }
  const float* data() const { return pixels_.data(); }
  Buffer<float>& pixels() { return pixels_; }
  const Buffer<float>& pixels() const { return pixels_; }
  float& operator()(int x, int y, int c = 0) {
    return pixels_[(std::size_t(y) * std::size_t(width_) + std::size_t(x)) * channels_ + c];
  }
  float operator()(int x, int y, int c = 0) const {
    return pixels_[(std::size_t(y) * std::size_t(width_) + std::size_t(x)) * channels_ + c];
  }
  MutableImageView view() { return {pixels_.data(), width_, height_, channels_}; }
  ConstImageView view() const { return {pixels_.data(), width_, height_, channels_}; }

 private:
  int width_ = 0, height_ = 0, channels_ = 1;
  Buffer<float> pixels_;
};

/// Throws std::invalid_argument unless `a` and `b` have the same width and height.
template <class A, class B>
void require_same_size(const std::string& name_a, const A& a, const std::string& name_b,
                       const B& b) {
  if (a.width != b.width || a.height != b.height)
    throw_invalid(name_b,
                  "must have the size of " + name_a + " (" + std::to_string(a.width) + "x" +
                      std::to_string(a.height) + ")",
                  std::to_string(b.width) + "x" + std::to_string(b.height));
}

}  // namespace aolab
