#include "core/methods/alchemy/alchemy.h"

#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "core/base/parallel.h"
#include "core/methods/hbao/hbao.h"
#include "core/sampling/random.h"

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
  const HbaoReceiver p = hbao_receiver(
      f.cam, x, y, d, {f.normals[3 * idx], f.normals[3 * idx + 1], f.normals[3 * idx + 2]});
  // The disc of radius r at depth d, projected: r·fx/d pixels across, r·fy/d down (§3).
  const float rx = s.radius * f.cam.fx / d, ry = s.radius * f.cam.fy / d;
  const float phi = s.random_rotation
                        ? 2.0f * std::numbers::pi_v<float> * pixel_random(std::uint32_t(s.seed), x, y, 0)
                        : 0.0f;
  const float cr = std::cos(phi), sr = std::sin(phi);
  const double bias = double(s.bias) * d;  // −z_C·β with z_C = −d
  double sum = 0.0;
  for (int i = 0; i < taps.size(); ++i) {
    float c, sn;
    taps.direction(i, cr, sr, c, sn);
    const float a = taps.alpha(i);
    const float sx_f = p.px + a * c * rx, sy_f = p.py - a * sn * ry;  // image y points down
    // A tap off the image sees nothing (and the test rejects inf/NaN at huge radii).
    if (!(sx_f >= 0.0f && sx_f < float(f.width) && sy_f >= 0.0f && sy_f < float(f.height)))
      continue;
    const int sx = int(sx_f), sy = int(sy_f);  // the texel the tap falls in
    if (sx == x && sy == y) continue;          // C itself: v = 0
    const float ds = f.depth[std::size_t(sy) * f.width + sx];
    if (!(ds == ds)) continue;  // background never occludes
    sum += obscurance_tap(p, sx, sy, ds, bias, e);
  }
  return e.visibility(sum);
}

}  // namespace

Image alchemy(const GBuffer& g, const AlchemySettings& s, const RunOptions& options) {
  g.validate();
  require_normal(g, "alchemy");
  validate_settings(s, kAlchemyFields);
  const int w = g.width(), h = g.height();
  const int threads = resolve_threads(options.threads);

  const std::vector<float> depth = depth_with_background_as_nan(g, threads);
  const Image normals = prepared_normals(g, threads);
  const Frame frame{depth.data(), normals.data(), w, h, g.camera};
  const SpiralTaps taps(s.samples, s.turns);
  const ObscuranceEstimator e(s.radius, s.samples, s.intensity, s.epsilon, s.contrast, s.falloff);

  Image out(w, h, 1, 1.0f);
  if (options.progress) options.progress->total += h;
  parallel_for_rows(
      h, threads,
      [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y)
          for (int x = 0; x < w; ++x) out(x, y) = alchemy_pixel(frame, s, taps, e, x, y);
      },
      options.progress);
  return out;
}

Method alchemy_method() {
  Method m = registered_method(
      "alchemy", "Alchemy screen-space ambient obscurance",
      "McGuire, Osman, Bukowski, Hennessy 2011, The Alchemy Screen-Space Ambient Obscurance "
      "Algorithm",
      kAlchemyFields, alchemy);
  m.needs_normal = true;
  return m;
}

}  // namespace aolab
