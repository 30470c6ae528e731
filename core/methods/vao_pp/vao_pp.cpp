#include "core/methods/vao_pp/vao_pp.h"

#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "core/base/parallel.h"
#include "core/methods/vao_pp/bilateral.h"
#include "core/methods/vao_pp/vao_pp_shared.h"
#include "core/sampling/poisson_disk.h"
#include "core/sampling/random.h"
#include "core/volumetric/pipes_simd.h"

namespace aolab {

float vao_pp_luminance_factor(float lum, float threshold, float width, float sigma) {
  // Eq. 3 prints min(1, max(0, lum - threshold + width)) / (2 width); the clamp is taken after
  // the division (docs: the printed order gives a negative base above threshold + width).
  const float t = std::clamp((lum - threshold + width) / (2.0f * width), 0.0f, 1.0f);
  return std::pow(1.0f - t, sigma);
}

float vao_pp_lum(const float rgb[3], int mode) {
  if (mode == 1) return std::max(rgb[0], std::max(rgb[1], rgb[2]));
  return 0.2126f * rgb[0] + 0.7152f * rgb[1] + 0.0722f * rgb[2];
}

int vao_pp_adaptive_samples(float diameter, float min_diameter, int max_samples) {
  const double area_ratio = (double(diameter) / min_diameter) * (double(diameter) / min_diameter);
  if (!(area_ratio >= 2.0)) return std::min(kVaoPpMinSamples, max_samples);
  if (!std::isfinite(area_ratio)) return max_samples;
  int exponent;
  std::frexp(area_ratio, &exponent);  // area_ratio = m·2^e, m in [0.5, 1): floor(log2) = e - 1
  const int doublings = exponent - 1;
  return doublings >= 5 ? max_samples : std::min(max_samples, kVaoPpMinSamples << doublings);
}

namespace {

using vao_pp_detail::Counters;
using vao_pp_detail::cull_prepass_simd;
using vao_pp_detail::occlusion_pass_simd;
using vao_pp_detail::Pass;

constexpr int kSetSizes[] = {2, 4, 8, 16, 32};

int set_index(int n) {
  int i = 0;
  while (kSetSizes[i] != n) ++i;
  return i;
}

// The sample sets of §4.1 and §4.5. Poisson: per size, the 9 rotations of the 3×3 tile
// (tile (x mod 3, y mod 3) takes rotation (x mod 3) + 3 (y mod 3)), all turned by the seed's
// angle. Spiral: per size one set, turned per pixel by a random angle.
class SampleSets {
 public:
  SampleSets(bool poisson, int seed) : poisson_(poisson), seed_(std::uint32_t(seed)) {
    seed_angle_ = seed ? float(2.0 * std::numbers::pi) * pixel_random(seed_, -1, -1, 7) : 0.0f;
    for (int s = 0; s < 5; ++s) {
      const int n = kSetSizes[s];
      if (poisson) {
        const VaoKernel base = vao_kernel(rotation_aware_poisson_disk(n).points);
        for (int k = 0; k < kPoissonRotations; ++k)
          sets_[s].push_back(rotated(base, tile_angle(k)));
      } else {
        sets_[s].push_back(vao_spiral_kernel(n));
      }
    }
  }

  // The set of n samples for pixel (x, y); `scratch` holds a per-pixel rotation.
  const VaoKernel& get(int n, int x, int y, VaoKernel& scratch) const {
    const auto& sets = sets_[set_index(n)];
    if (poisson_) return sets[std::size_t((x % 3) + 3 * (y % 3))];
    vao_random_rotation(sets[0], seed_, x, y, scratch);
    return scratch;
  }

  // The same sets for the SIMD kernel: the unrotated ones and the tile's nine angles.
  VaoSimdSets simd() const {
    VaoSimdSets out;
    for (int n : kSetSizes)
      out.add(poisson_ ? vao_kernel(rotation_aware_poisson_disk(n).points) : vao_spiral_kernel(n));
    out.tiled = poisson_;
    for (int k = 0; k < kPoissonRotations; ++k) {
      const double angle = double(tile_angle(k));  // as `rotated` turns it
      out.rotation_cos[k] = float(std::cos(angle));
      out.rotation_sin[k] = float(std::sin(angle));
    }
    out.random_rotation = !poisson_;
    out.seed = seed_;
    return out;
  }

 private:
  // The angle of the tile's rotation k, turned by the seed's.
  float tile_angle(int k) const {
    return seed_angle_ + float(2.0 * std::numbers::pi * k / kPoissonRotations);
  }

  bool poisson_;
  std::uint32_t seed_;
  float seed_angle_ = 0.0f;
  std::array<std::vector<VaoKernel>, 5> sets_;
};

bool is_power_of_two_set(int n) {
  for (int s : kSetSizes)
    if (s == n) return true;
  return false;
}

// §4.2: the bilinear fetch of the low-resolution AO (texel centres at (i + 0.5)·8, clamped
// to the edge) at each of the pixel's four corners; occlusion if any is below the threshold.
bool occlusion_nearby(const Image& low, int x, int y, float threshold) {
  const int lw = low.width(), lh = low.height();
  auto texel = [&](int i, int j) {
    return low(std::clamp(i, 0, lw - 1), std::clamp(j, 0, lh - 1));
  };
  for (int b = 0; b <= 1; ++b)
    for (int a = 0; a <= 1; ++a) {
      const float u = float(x + a) / float(kVaoPpCullFactor) - 0.5f;
      const float v = float(y + b) / float(kVaoPpCullFactor) - 0.5f;
      const float fu = std::floor(u), fv = std::floor(v);
      const int i = int(fu), j = int(fv);
      const float tu = u - fu, tv = v - fv;
      const float top = texel(i, j) + tu * (texel(i + 1, j) - texel(i, j));
      const float bottom = texel(i, j + 1) + tu * (texel(i + 1, j + 1) - texel(i, j + 1));
      if (top + tv * (bottom - top) < threshold) return true;
    }
  return false;
}

// The setting that makes VAO++ read colour ("" = none); colour bleeding is named first.
std::string color_setting(bool color_bleeding, bool luminance_sensitivity) {
  if (color_bleeding) return "color_bleeding";
  if (luminance_sensitivity) return "luminance_sensitivity";
  return "";
}

void validate_vao_pp(const GBuffer& g, const VaoPpSettings& s) {
  g.validate();
  require_normal(g, "vao_pp");
  validate_settings(s, kVaoPpFields);
  if (!is_power_of_two_set(s.samples))
    throw_invalid("samples", "must be 2, 4, 8, 16 or 32 (the sample sets of 4.1)", s.samples);
  if (s.filter_taps % 2 == 0) throw_invalid("filter_taps", "must be odd", s.filter_taps);
  if (s.bleeding_sample_step == 3)
    throw_invalid("bleeding_sample_step", "must be 1, 2 or 4", s.bleeding_sample_step);
  if (const std::string setting = color_setting(s.color_bleeding, s.luminance_sensitivity);
      !setting.empty())
    require_color(g, "vao_pp", setting);
}

// §4.2: AO at 1/8 resolution, 8 samples, at the pixel nearest each low-res texel's centre.
Image cull_prepass(const Pass& r, const SampleSets& sets, Counters& counters) {
  const int w = r.frame.width, h = r.frame.height;
  const int lw = (w + kVaoPpCullFactor - 1) / kVaoPpCullFactor;
  const int lh = (h + kVaoPpCullFactor - 1) / kVaoPpCullFactor;
  Image low(lw, lh, 1, 1.0f);
  parallel_for_rows(
      lh, r.threads,
      [&](int j0, int j1) {
        VaoKernel scratch;
        std::int64_t count = 0;
        for (int j = j0; j < j1; ++j)
          for (int i = 0; i < lw; ++i) {
            const int x = std::min(i * kVaoPpCullFactor + kVaoPpCullFactor / 2, w - 1);
            const int y = std::min(j * kVaoPpCullFactor + kVaoPpCullFactor / 2, h - 1);
            if (!r.geometry(x, y)) continue;
            const VaoKernel& k = sets.get(kVaoPpCullSamples, x, y, scratch);
            low(i, j) =
                vao_pixel(r.frame, r.po, x, y, k.x.data(), k.y.data(), k.h.data(), k.size()).ao();
            ++count;
          }
        counters.prepass_pixels += count;
      },
      r.progress);
  return low;
}

// The samples of geometry pixel (x, y): §4.1's adaptive count, cut by §4.2's culling where
// the pre-pass found no occlusion nearby (`culled`); 0 = culled greedily (left at 1).
int pixel_samples(const Pass& r, const Image& low, int x, int y, bool& culled) {
  const VaoPpSettings& s = r.s;
  int n = s.samples;
  if (s.adaptive_sampling) {
    // §4.1: the disc of diameter R at the sphere centre's depth, projected.
    const std::size_t idx = std::size_t(y) * r.frame.width + x;
    const float dc = r.frame.depth[idx] - 0.5f * s.radius * r.frame.normals.data()[3 * idx + 2];
    const float inv_height = 1.0f / float(r.frame.height);
    const float diameter = dc > 0.0f ? s.radius * r.g.camera.fy / dc * inv_height : INFINITY;
    n = vao_pp_adaptive_samples(diameter, s.adaptive_min_diameter, s.samples);
  }
  culled = r.culling != VaoPpCulling::Off && !occlusion_nearby(low, x, y, s.cull_threshold);
  if (!culled) return n;
  return r.culling == VaoPpCulling::Greedy ? 0 : std::min(n, kVaoPpCarefulSamples);
}

// Pass 1 (§3): occlusion, and with colour bleeding the bleed colour B, into a working image
// of 1 or 4 channels (A, B_r, B_g, B_b).
Image occlusion_pass(const Pass& r, const SampleSets& sets, const Image& low, Counters& counters) {
  const VaoPpSettings& s = r.s;
  const int w = r.frame.width, h = r.frame.height;
  Image work(w, h, s.color_bleeding ? 4 : 1, 1.0f);
  VaoPixelOptions full_po = r.po;
  full_po.bleeding_step = s.color_bleeding ? s.bleeding_sample_step : 0;
  parallel_for_rows(
      h, r.threads,
      [&](int y0, int y1) {
        VaoKernel scratch;
        std::int64_t band_pixels = 0, band_culled = 0, band_samples = 0;
        for (int y = y0; y < y1; ++y)
          for (int x = 0; x < w; ++x) {
            if (!r.geometry(x, y)) continue;
            ++band_pixels;
            bool culled;
            const int n = pixel_samples(r, low, x, y, culled);
            band_culled += culled;
            if (n == 0) continue;  // greedy culling: left at 1 (and white)
            const VaoKernel& k = sets.get(n, x, y, scratch);
            const VaoPixelSums sums =
                vao_pixel(r.frame, full_po, x, y, k.x.data(), k.y.data(), k.h.data(), k.size());
            band_samples += n;
            work(x, y, 0) = sums.ao();
            if (s.color_bleeding && sums.bleed_count > 0)
              for (int c = 0; c < 3; ++c)
                work(x, y, 1 + c) = sums.bleed[c] / float(sums.bleed_count);
          }
        counters.pixels += band_pixels;
        counters.culled += band_culled;
        counters.samples += band_samples;
      },
      r.progress);
  return work;
}

// Pass 3: luminance sensitivity (eq. 3) on the occlusion 1 − A of the geometry pixels.
void apply_luminance(const Pass& r, Image& work) {
  const GBuffer& g = r.g;
  const VaoPpSettings& s = r.s;
  parallel_for_rows(g.height(), r.threads, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < g.width(); ++x) {
        if (!r.geometry(x, y)) continue;
        float rgb[3];
        for (int c = 0; c < 3; ++c) {
          float v = g.color(x, y, c) + (g.has_emission() ? g.emission(x, y, c) : 0.0f);
          rgb[c] = std::isfinite(v) ? v : 0.0f;
        }
        const float factor =
            vao_pp_luminance_factor(vao_pp_lum(rgb, s.luminance_mode), s.luminance_threshold,
                                    s.luminance_width, s.luminance_sigma);
        work(x, y, 0) = 1.0f - (1.0f - work(x, y, 0)) * factor;
      }
  });
}

// Colour bleeding's result: A·B per channel, clamped to [0, 1].
Image bleeding_result(const Image& work, int threads) {
  const int w = work.width(), h = work.height();
  Image out(w, h, 3);
  parallel_for_rows(h, threads, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < 3; ++c)
          out(x, y, c) = std::clamp(work(x, y, 0) * work(x, y, 1 + c), 0.0f, 1.0f);
  });
  return out;
}

}  // namespace

Image vao_pp(const GBuffer& g, const VaoPpSettings& s, const RunOptions& options,
             VaoPpStats* stats) {
  validate_vao_pp(g, s);
  const int h = g.height();
  const int threads = resolve_threads(options.threads);
  const VaoFrame frame = vao_frame(g, s.color_bleeding, threads);
  const SampleSets sets(s.poisson_samples, s.seed);
  Pass r{g, s, frame, {}, VaoPpCulling(s.culling), threads, options.progress};
  r.po.radius = s.radius;
  r.po.view_ray_pipes = s.view_ray_pipes;
  r.po.range_check = s.range_check;

  const bool culling = r.culling != VaoPpCulling::Off;
  const int lh = (h + kVaoPpCullFactor - 1) / kVaoPpCullFactor;
  if (options.progress) options.progress->total += (culling ? lh : 0) + h;
  Counters counters;
  Image work;
  if (options.kernel == Kernel::Simd) {
    const VaoSimdSets simd_sets = sets.simd();
    const Image low = culling ? cull_prepass_simd(r, simd_sets, counters) : Image();
    work = occlusion_pass_simd(r, simd_sets, low, counters);
  } else {
    const Image low = culling ? cull_prepass(r, sets, counters) : Image();
    work = occlusion_pass(r, sets, low, counters);
  }
  // Pass 2 (§4.6): the cross-bilateral low-pass, depth threshold R.
  if (s.filter)
    work = options.kernel == Kernel::Simd
               ? cross_bilateral_filter_simd(work.view(), frame.depth.data(), s.filter_taps,
                                             s.filter_sigma, s.radius, threads, options.progress)
               : cross_bilateral_filter(work.view(), g, s.filter_taps, s.filter_sigma, s.radius,
                                        threads, options.progress);
  if (s.luminance_sensitivity) apply_luminance(r, work);
  if (stats) {
    stats->pixels = counters.pixels;
    stats->culled = counters.culled;
    stats->samples = counters.samples;
    stats->prepass_pixels = counters.prepass_pixels;
  }
  if (!s.color_bleeding) return work;
  return bleeding_result(work, threads);
}

Method vao_pp_method() {
  Method m = registered_method(
      "vao_pp", "VAO++: practical volumetric ambient occlusion",
      "Boksansky, Pospisil, Bittner 2017, VAO++: Practical Volumetric Ambient Occlusion "
      "for Games",
      kVaoPpFields, [](const GBuffer& g, const VaoPpSettings& s, const RunOptions& options) {
        return vao_pp(g, s, options);
      });
  m.needs_normal = true;
  m.needs_color = true;                // with luminance_sensitivity or color_bleeding only
  m.color_depends_on_settings = true;  // validate_vao_pp checks it
  m.has_simd_kernel = true;
  return m;
}

}  // namespace aolab
