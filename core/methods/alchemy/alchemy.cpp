#include "core/methods/alchemy/alchemy.h"

#include <vector>

#include "core/base/parallel.h"
#include "core/horizon/obscurance_simd.h"

namespace aolab {

namespace {

struct Frame {
  const float* depth;    // background replaced by NaN, so every test on it fails
  const float* normals;  // prepared, 3 per pixel
  int width, height;
  CameraIntrinsics cam;
};

float alchemy_pixel(const Frame& f, const AlchemySettings& s, const SpiralTaps& taps,
                    const ObscuranceEstimator& e, int x, int y) {
  const std::size_t idx = std::size_t(y) * f.width + x;
  const float d = f.depth[idx];
  if (!(d == d)) return 1.0f;  // background
  const glm::vec3 n(f.normals[3 * idx], f.normals[3 * idx + 1], f.normals[3 * idx + 2]);
  const double bias = double(s.bias) * d;  // −z_C·β with z_C = −d (§3)
  return obscurance_estimate(f.cam, x, y, d, n, s.radius, s.random_rotation, s.seed, bias, taps, e,
                             f.width, f.height, [&](int, int sx, int sy, float& ds) {
                               ds = f.depth[std::size_t(sy) * f.width + sx];
                               return ds == ds;
                             });
}

}  // namespace

Image alchemy(const GBuffer& g, const AlchemySettings& s, const RunOptions& options) {
  g.validate();
  require_normal(g, "alchemy");
  validate_settings(s, kAlchemyFields);
  const int w = g.width(), h = g.height();
  const int threads = resolve_threads(options.threads);

  const Buffer<float> depth = depth_with_background_as_nan(g, threads);
  const Image normals = prepared_normals(g, threads);
  const Frame frame{depth.data(), normals.data(), w, h, g.camera};
  const SpiralTaps taps(s.samples, s.turns);
  const ObscuranceEstimator e(s.radius, s.samples, s.intensity, s.epsilon, s.contrast, s.falloff);
  if (options.kernel == Kernel::Simd) {
    // b = β·d, in units of r for the kernel.
    const ObscuranceSimdFrame sf{depth.data(),
                                 normals.data(),
                                 w,
                                 h,
                                 g.camera,
                                 s.radius,
                                 s.random_rotation,
                                 s.seed,
                                 float(double(s.bias) / s.radius),
                                 0.0f,
                                 &taps,
                                 &e,
                                 nullptr};
    return obscurance_simd(sf, threads, options.progress);
  }

  return image_from_pixels(
      w, h, threads, options.progress, [] { return 0; },
      [&](int, int x, int y) { return alchemy_pixel(frame, s, taps, e, x, y); });
}

Method alchemy_method() {
  Method m = registered_method(
      "alchemy", "Alchemy screen-space ambient obscurance",
      "McGuire, Osman, Bukowski, Hennessy 2011, The Alchemy Screen-Space Ambient Obscurance "
      "Algorithm",
      kAlchemyFields, alchemy);
  m.needs_normal = true;
  m.has_simd_kernel = true;
  return m;
}

}  // namespace aolab
