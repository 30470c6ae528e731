#include "core/filters/temporal.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "core/base/parallel.h"
#include "core/filters/temporal_pixel.h"

namespace aolab {

namespace {

/// What reprojection found for one pixel: the renormalised bilinear history and the shortest
/// history length among its kept taps; `found` false = disocclusion.
struct Reprojected {
  double ao = 0.0;
  float length = 0.0f;
  bool found = false;
};

/// Whether the history tap at (x, y) shows the surface the current pixel shows: its stored
/// depth within depth_tolerance of d (relative) and its normal within normal_tolerance.
/// Background in the history (depth NaN) always fails.
bool keeps_tap(const TemporalHistory& h, int x, int y, float d, const float* n,
               const TemporalSettings& s) {
  const float hd = h.depth(x, y);
  if (!(std::abs(hd - d) <= s.depth_tolerance * d)) return false;
  if (s.normal_tolerance <= -1.0f) return true;
  const float cosine =
      h.normal(x, y, 0) * n[0] + h.normal(x, y, 1) * n[1] + h.normal(x, y, 2) * n[2];
  return cosine >= s.normal_tolerance;
}

/// Bilinear history at the previous-frame position of pixel (x, y): its centre (x + 0.5,
/// y + 0.5) moved by (dx, dy), i.e. (x + dx, y + dy) in the coordinates where pixel k's
/// centre is k. Taps of weight 0 are not read (an integer offset reads one tap, exactly);
/// taps outside the image or rejected by keeps_tap drop out and the rest are renormalised.
Reprojected reproject(const TemporalHistory& h, int x, int y, float dx, float dy, float d,
                      const float* n, const TemporalSettings& s) {
  if (!std::isfinite(dx) || !std::isfinite(dy)) return {};
  const double px = double(x) + double(dx), py = double(y) + double(dy);
  const int w = h.width(), ht = h.height();
  if (!(px > -1.0 && px < double(w) && py > -1.0 && py < double(ht))) return {};  // off-screen
  const double fx0 = std::floor(px), fy0 = std::floor(py);
  const int x0 = int(fx0), y0 = int(fy0);
  const double fx = px - fx0, fy = py - fy0;
  const double weights[4] = {(1.0 - fx) * (1.0 - fy), fx * (1.0 - fy), (1.0 - fx) * fy, fx * fy};
  double sum = 0.0, wsum = 0.0;
  float length = 0.0f;
  for (int t = 0; t < 4; ++t) {
    const int tx = x0 + (t & 1), ty = y0 + (t >> 1);
    if (weights[t] == 0.0 || tx < 0 || ty < 0 || tx >= w || ty >= ht) continue;
    if (!keeps_tap(h, tx, ty, d, n, s)) continue;
    sum += weights[t] * double(h.ao(tx, ty));
    length = wsum == 0.0 ? h.length(tx, ty) : std::min(length, h.length(tx, ty));
    wsum += weights[t];
  }
  if (wsum == 0.0) return {};
  return {sum / wsum, length, true};
}

/// [lo, hi] the history is clamped to: the range of the current AO over the geometry pixels
/// of the 3x3 neighbourhood of (x, y) (Karis 2014), for Variance narrowed to mean ± γσ
/// (Salvi 2016). The mean lies in the range, so the narrowed interval is never empty.
void clamp_range(ConstImageView ao, const GBuffer& g, int x, int y, const TemporalSettings& s,
                 double& lo, double& hi) {
  lo = ao(x, y), hi = lo;
  double sum = 0.0, sum2 = 0.0;
  int count = 0;
  for (int yy = std::max(0, y - 1); yy <= std::min(g.height() - 1, y + 1); ++yy)
    for (int xx = std::max(0, x - 1); xx <= std::min(g.width() - 1, x + 1); ++xx) {
      if (!g.valid(xx, yy)) continue;
      const double v = ao(xx, yy);
      lo = std::min(lo, v), hi = std::max(hi, v);
      sum += v, sum2 += v * v, ++count;
    }
  if (TemporalClamp(s.clamp) != TemporalClamp::Variance) return;
  const double mean = sum / count;
  const double sigma = std::sqrt(std::max(0.0, sum2 / count - mean * mean));
  lo = std::max(lo, mean - s.variance_gamma * sigma);
  hi = std::min(hi, mean + s.variance_gamma * sigma);
}

void validate_history(const TemporalHistory& h, const GBuffer& g) {
  if (h.empty()) return;
  const auto size = [](const Image& i) {
    return std::to_string(i.width()) + "x" + std::to_string(i.height()) + "x" +
           std::to_string(i.channels());
  };
  const std::string want = std::to_string(g.width()) + "x" + std::to_string(g.height()) + "x";
  const std::pair<const Image*, int> parts[] = {
      {&h.ao, 1}, {&h.length, 1}, {&h.depth, 1}, {&h.normal, 3}};
  for (const auto& [image, channels] : parts)
    if (image->width() != g.width() || image->height() != g.height() ||
        image->channels() != channels)
      throw_invalid("history",
                    "must be empty (frame 0) or from frames of this size (" + want +
                        "1, normals x3; reset it when the size changes)",
                    size(*image));
}

/// AO must be finite where it is blended: a NaN would live on in the history.
void validate_ao(ConstImageView ao, const GBuffer& g) {
  for (int y = 0; y < ao.height; ++y)
    for (int x = 0; x < ao.width; ++x)
      if (g.valid(x, y) && !std::isfinite(ao(x, y)))
        throw_invalid("ao",
                      "must be finite on geometry pixels (at " + std::to_string(x) + ", " +
                          std::to_string(y) + ")",
                      ao(x, y));
}

}  // namespace

void accumulate_pixel(const TemporalFrame& f, int x, int y) {
  const TemporalSettings& s = f.settings;
  const float d = f.g.depth(x, y), c = f.ao(x, y);
  f.accumulated(x, y) = c;  // background, disocclusion: the current frame exactly
  f.disoccluded(x, y) = 0.0f;
  if (!f.g.valid(x, y)) {
    f.depth(x, y) = std::numeric_limits<float>::quiet_NaN();
    f.length(x, y) = 0.0f;  // not disoccluded: there is no surface to have history
    return;
  }
  f.depth(x, y) = d;
  const float* n =
      f.normals.data() + (std::size_t(y) * std::size_t(f.g.width()) + std::size_t(x)) * 3;
  const Reprojected r =
      f.history.empty() ? Reprojected{}
                        : reproject(f.history, x, y, f.motion(x, y, 0), f.motion(x, y, 1), d, n, s);
  if (!r.found) {
    f.disoccluded(x, y) = 1.0f;
    f.length(x, y) = 1.0f;
    return;
  }
  double past = r.ao;
  if (TemporalClamp(s.clamp) != TemporalClamp::Off) {
    double lo = 0.0, hi = 0.0;
    clamp_range(f.ao, f.g, x, y, s, lo, hi);
    past = std::clamp(past, lo, hi);
  }
  // w = max(α, 1/(n + 1)): the running mean until it reaches α, then the exponential
  // average (Karis 2014's blend with a start that weighs every frame alike).
  const double weight = std::max(double(s.alpha), 1.0 / (double(r.length) + 1.0));
  f.accumulated(x, y) = float(past + weight * (double(c) - past));
  f.length(x, y) = std::min(r.length + 1.0f, float(s.max_history));
}

TemporalResult accumulate(ConstImageView ao, const GBuffer& g, ConstImageView motion,
                          TemporalHistory& history, const TemporalSettings& s, int threads,
                          TemporalKernel kernel) {
  validate_settings(s, kTemporalFields);
  resolve_threads(threads);
  g.validate();
  if (ao.channels != 1) throw_invalid("ao", "must have 1 channel", ao.channels);
  if (motion.channels != 2)
    throw_invalid("motion", "must have 2 channels (dx, dy in pixels)", motion.channels);
  require_same_size("depth", g.depth, "ao", ao);
  require_same_size("depth", g.depth, "motion", motion);
  validate_history(history, g);
  validate_ao(ao, g);

  const int w = g.width(), h = g.height();
  Image normals = prepared_normals(g, threads);
  Image depth(w, h, 1), length(w, h, 1);
  TemporalResult out{Image(w, h, 1), Image(w, h, 1)};
  const TemporalFrame frame{
      ao, g, motion, history, s, normals, out.accumulated, out.disoccluded, depth, length};
  parallel_for_rows(h, threads, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      if (kernel == TemporalKernel::Simd) {
        accumulate_row_simd(frame, y);
        continue;
      }
      for (int x = 0; x < w; ++x) accumulate_pixel(frame, x, y);
    }
  });
  history.ao = out.accumulated;
  history.length = std::move(length);
  history.depth = std::move(depth);
  history.normal = std::move(normals);
  return out;
}

std::vector<SettingDescription> temporal_setting_descriptions() {
  return describe_settings(kTemporalFields);
}

}  // namespace aolab
