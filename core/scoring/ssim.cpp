// SSIM as in Wang et al. 2004 and scikit-image's structural_similarity with gaussian_weights:
// five Gaussian-filtered planes (a, b, a², b², ab; scipy.ndimage.gaussian_filter with mode
// 'reflect'), population moments from them, eq. (13) per pixel, eq. (17) mean over the interior.
//
// The filter is separable. Rows are processed in blocks: a block first filters horizontally the
// rows it needs (its own rows and `radius` reflected rows above and below), then vertically,
// and hands each finished row of S to the caller. Every S value is computed by the same
// arithmetic whichever block computes it, so the result does not depend on the thread count.
#include "core/scoring/ssim.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/base/check.h"
#include "core/base/parallel.h"
#include "core/scoring/metrics.h"

namespace aolab {

namespace {

// Rows per work unit. parallel_for_rows hands out a few units at a time and each call filters
// its rows as one block, so a block recomputes 2·radius rows of horizontal filtering; with
// units of 8 rows (blocks of a few dozen) that overhead stays small while 1080p still splits
// into more blocks than there are cores.
constexpr int kRowsPerUnit = 8;

// A window wider than this is surely a mistake (sigma in the wrong unit), and would only
// allocate huge scratch rows.
constexpr double kMaxRadius = 1024;

// Number of filtered planes: a, b, a², b², a·b.
constexpr int kPlanes = 5;

void require_positive_finite(const std::string& name, double value) {
  if (!(std::isfinite(value) && value > 0)) throw_invalid(name, "must be finite and > 0", value);
}

// scipy.ndimage's 'reflect' extension (half-sample symmetric, d c b a | a b c d | d c b a):
// periodic with period 2n, mirrored in the second half. Valid for any i, also when |i| > n,
// which happens for images narrower than the window.
int reflect(int i, int n) {
  const int period = 2 * n;
  int m = i % period;
  if (m < 0) m += period;
  return m < n ? m : period - 1 - m;
}

// The normalised Gaussian taps of scipy's _gaussian_kernel1d: exp(−x² / 2σ²), x in [−r, r],
// divided by their sum.
std::vector<double> gaussian_weights(double sigma, int radius) {
  std::vector<double> w(std::size_t(2 * radius + 1));
  const double scale = -0.5 / (sigma * sigma);
  double sum = 0;
  for (int x = -radius; x <= radius; ++x) {
    const double v = std::exp(scale * double(x) * double(x));
    w[std::size_t(x + radius)] = v;
    sum += v;
  }
  for (double& v : w) v /= sum;
  return w;
}

// The horizontal pass of one block: the five planes (a, b, a², b², ab) of the reflected
// source rows y0 − r … y0 − r + rows − 1, each plane rows × width in `h`. Where `mask` is
// non-empty and zero, both images read as 1. pa, pb: scratch of the padded width.
void filter_block_rows(ConstImageView a, ConstImageView b, ConstImageView mask,
                       const std::vector<double>& w, const std::vector<int>& column, int r, int y0,
                       int rows, std::vector<double>& h, std::vector<double>& pa,
                       std::vector<double>& pb) {
  const int width = a.width, height = a.height, taps = 2 * r + 1;
  const std::size_t plane = std::size_t(rows) * std::size_t(width);
  for (int e = 0; e < rows; ++e) {
    const int sy = reflect(y0 - r + e, height);
    const float* ra = a.row(sy);
    const float* rb = b.row(sy);
    const float* rm = mask.empty() ? nullptr : mask.row(sy);
    for (std::size_t i = 0; i < column.size(); ++i) {
      const int sx = column[i];
      const bool background = rm && rm[sx] == 0.0f;
      pa[i] = background ? 1.0 : double(ra[sx]);
      pb[i] = background ? 1.0 : double(rb[sx]);
    }
    double* out = h.data() + std::size_t(e) * std::size_t(width);
    for (int x = 0; x < width; ++x) {
      double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
      for (int t = 0; t < taps; ++t) {
        const double wt = w[std::size_t(t)];
        const double va = pa[std::size_t(x + t)], vb = pb[std::size_t(x + t)];
        sa += wt * va;
        sb += wt * vb;
        saa += wt * (va * va);
        sbb += wt * (vb * vb);
        sab += wt * (va * vb);
      }
      out[x] = sa;
      out[plane + std::size_t(x)] = sb;
      out[2 * plane + std::size_t(x)] = saa;
      out[3 * plane + std::size_t(x)] = sbb;
      out[4 * plane + std::size_t(x)] = sab;
    }
  }
}

// Eq. (13) from the moments, clamped to [−1, 1] (which it cannot leave mathematically; the
// clamp only removes rounding).
double ssim_value(double ua, double ub, double va, double vb, double vab, const SsimConstants& k) {
  const double a1 = 2 * ua * ub + k.c1;
  const double a2 = 2 * vab + k.c2;
  const double b1 = ua * ua + ub * ub + k.c1;
  const double b2 = va + vb + k.c2;
  return std::clamp((a1 * a2) / (b1 * b2), -1.0, 1.0);
}

// The moments as the fast path computes them, E[a²] − E[a]², lose every digit when the
// values are large compared with their spread within the window (a constant 1e20 gives a
// variance of rounding noise around 1e24 instead of 0, and SSIM(+1e20, −1e20) came out 1).
// Their rounding error is at most about kCancellation · (E[a²] + E[b²]); where that is not
// negligible against the denominator σa² + σb² + C2 the pixel is recomputed by exact_ssim.
// For AO in [0, 1] (E[a²] + E[b²] <= 2, denominator >= C2 = 9e-4) this never happens, so
// the fast path's bits are unchanged there.
constexpr double kCancellation = 64 * std::numeric_limits<double>::epsilon();
constexpr double kTolerance = 1e-9;

bool needs_exact(double uaa, double ubb, double va, double vb, const SsimConstants& k) {
  const double denominator = std::max(va, 0.0) + std::max(vb, 0.0) + k.c2;
  return !(kCancellation * (uaa + ubb) <= kTolerance * denominator);
}

// S at (x, y) straight from the window, with the values taken relative to the window's
// centre pixel: the moments of the differences have no cancellation against the values'
// magnitude (a constant window has differences exactly 0), so S is accurate for any finite
// float input, however large. Same reflection and mask rule as the fast path.
double exact_ssim(ConstImageView a, ConstImageView b, ConstImageView mask,
                  const std::vector<double>& w, const SsimConstants& k, int x, int y) {
  const auto value = [&](ConstImageView image, int sx, int sy) {
    if (!mask.empty() && mask.row(sy)[sx] == 0.0f) return 1.0;
    return double(image.row(sy)[sx]);
  };
  const double ca = value(a, x, y), cb = value(b, x, y);
  const int r = k.radius;
  double da = 0, db = 0, daa = 0, dbb = 0, dab = 0;
  for (int ty = -r; ty <= r; ++ty) {
    const int sy = reflect(y + ty, a.height);
    const double wy = w[std::size_t(ty + r)];
    for (int tx = -r; tx <= r; ++tx) {
      const int sx = reflect(x + tx, a.width);
      const double wt = wy * w[std::size_t(tx + r)];
      const double pa = value(a, sx, sy) - ca, pb = value(b, sx, sy) - cb;
      da += wt * pa;
      db += wt * pb;
      daa += wt * (pa * pa);
      dbb += wt * (pb * pb);
      dab += wt * (pa * pb);
    }
  }
  const double va = std::max(0.0, daa - da * da);
  const double vb = std::max(0.0, dbb - db * db);
  const double bound = std::sqrt(va) * std::sqrt(vb);  // Cauchy–Schwarz: |σab| <= σa σb
  const double vab = std::clamp(dab - da * db, -bound, bound);
  return ssim_value(ca + da, cb + db, va, vb, vab, k);
}

// One row of S from a block's horizontally filtered planes: the vertical pass over the taps
// starting at block row `e0`, then eq. (13) per pixel, in skimage's order of operations;
// pixels whose moments cancelled (needs_exact) are recomputed by exact_ssim.
// acc: scratch of 5·width.
void ssim_row(ConstImageView a, ConstImageView b, ConstImageView mask, int y,
              const std::vector<double>& h, std::size_t plane, int width, int e0,
              const std::vector<double>& w, const SsimConstants& k, std::vector<double>& acc,
              double* s) {
  std::fill(acc.begin(), acc.end(), 0.0);
  for (int t = 0; t < 2 * k.radius + 1; ++t) {
    const double wt = w[std::size_t(t)];
    const std::size_t row_offset = std::size_t(e0 + t) * std::size_t(width);
    for (int q = 0; q < kPlanes; ++q) {
      const double* src = h.data() + std::size_t(q) * plane + row_offset;
      double* dst = acc.data() + std::size_t(q) * std::size_t(width);
      for (int x = 0; x < width; ++x) dst[x] += wt * src[x];
    }
  }
  const double* ua = acc.data();
  const double* ub = ua + width;
  const double* uaa = ub + width;
  const double* ubb = uaa + width;
  const double* uab = ubb + width;
  for (int x = 0; x < width; ++x) {
    // Population (not sample) moments, eqs. (14)–(16): the Gaussian weights sum to 1.
    const double va = uaa[x] - ua[x] * ua[x];
    const double vb = ubb[x] - ub[x] * ub[x];
    const double vab = uab[x] - ua[x] * ub[x];
    s[std::size_t(x)] = needs_exact(uaa[x], ubb[x], va, vb, k)
                            ? exact_ssim(a, b, mask, w, k, x, y)
                            : ssim_value(ua[x], ub[x], va, vb, vab, k);
  }
}

// Computes S row by row and calls row_done(y, s) with the W values of row y (from worker
// threads, each row once). Inputs are assumed validated. Where `mask` is non-empty and zero,
// both images read as 1 (see mean_ssim).
template <class RowDone>
void compute_ssim_rows(ConstImageView a, ConstImageView b, ConstImageView mask,
                       const SsimConstants& k, const std::vector<double>& w, int threads,
                       const RowDone& row_done) {
  const int width = a.width, height = a.height, r = k.radius;
  const std::size_t padded = std::size_t(width + 2 * r);

  // Source column of every padded position, the same for every row.
  std::vector<int> column(padded);
  for (int i = 0; i < width + 2 * r; ++i) column[std::size_t(i)] = reflect(i - r, width);

  const int units = (height + kRowsPerUnit - 1) / kRowsPerUnit;
  parallel_for_rows(units, threads, [&](int u0, int u1) {
    const int y0 = u0 * kRowsPerUnit;
    const int y1 = std::min(height, u1 * kRowsPerUnit);
    const int rows = y1 - y0 + 2 * r;  // horizontally filtered rows y0 − r .. y1 + r − 1
    const std::size_t plane = std::size_t(rows) * std::size_t(width);
    std::vector<double> h(plane * kPlanes);
    std::vector<double> pa(padded), pb(padded);
    filter_block_rows(a, b, mask, w, column, r, y0, rows, h, pa, pb);
    std::vector<double> acc(std::size_t(width) * kPlanes);
    std::vector<double> s(static_cast<std::size_t>(width));
    for (int y = y0; y < y1; ++y) {
      ssim_row(a, b, mask, y, h, plane, width, y - y0, w, k, acc, s.data());
      row_done(y, s.data());
    }
  });
}

}  // namespace

SsimConstants ssim_constants(const SsimSettings& settings) {
  require_positive_finite("settings.sigma", settings.sigma);
  require_positive_finite("settings.truncate", settings.truncate);
  require_positive_finite("settings.k1", settings.k1);
  require_positive_finite("settings.k2", settings.k2);
  require_positive_finite("settings.data_range", settings.data_range);
  // scipy's radius: int(truncate · sigma + 0.5).
  const double radius = settings.truncate * settings.sigma + 0.5;
  if (radius > kMaxRadius)
    throw_invalid("settings.sigma",
                  "times settings.truncate must give a window radius <= " +
                      std::to_string(int(kMaxRadius)) + " px",
                  radius);
  SsimConstants k;
  k.radius = int(radius);
  // Wang et al. 2004: C1 = (K1 L)², C2 = (K2 L)².
  k.c1 = (settings.k1 * settings.data_range) * (settings.k1 * settings.data_range);
  k.c2 = (settings.k2 * settings.data_range) * (settings.k2 * settings.data_range);
  return k;
}

Image ssim_map(ConstImageView a, ConstImageView b, const SsimSettings& settings, int threads) {
  const SsimConstants k = ssim_constants(settings);
  require_comparable("a", a, "b", b, {}, threads);
  const std::vector<double> w = gaussian_weights(settings.sigma, k.radius);
  Image out(a.width, a.height, 1);
  compute_ssim_rows(a, b, {}, k, w, threads, [&](int y, const double* s) {
    float* dst = out.data() + std::size_t(y) * std::size_t(a.width);
    for (int x = 0; x < a.width; ++x) dst[x] = float(s[x]);
  });
  return out;
}

double mean_ssim(ConstImageView a, ConstImageView b, ConstImageView mask,
                 const SsimSettings& settings, int threads) {
  const SsimConstants k = ssim_constants(settings);
  require_comparable("a", a, "b", b, mask, threads);
  const bool masked = !mask.empty();
  const std::vector<double> w = gaussian_weights(settings.sigma, k.radius);

  // skimage's crop(S, radius): the interior, where the window reads no reflected pixel.
  const int r = k.radius;
  const int x_begin = r, x_end = a.width - r, y_begin = r, y_end = a.height - r;

  struct RowSums {
    double interior = 0, all = 0;
    std::int64_t interior_count = 0, all_count = 0;
  };
  std::vector<RowSums> rows(std::size_t(a.height));
  compute_ssim_rows(a, b, mask, k, w, threads, [&](int y, const double* s) {
    RowSums sums;
    const float* m = masked ? mask.row(y) : nullptr;
    const bool interior_row = y >= y_begin && y < y_end;
    for (int x = 0; x < a.width; ++x) {
      if (m && m[x] == 0.0f) continue;
      sums.all += s[x];
      ++sums.all_count;
      if (interior_row && x >= x_begin && x < x_end) {
        sums.interior += s[x];
        ++sums.interior_count;
      }
    }
    rows[std::size_t(y)] = sums;
  });
  RowSums total;
  for (const RowSums& s : rows) {  // rows in order: the same bits for any thread count
    total.interior += s.interior;
    total.all += s.all;
    total.interior_count += s.interior_count;
    total.all_count += s.all_count;
  }
  if (total.all_count == 0) throw_invalid("mask", "must select at least one pixel", 0);
  // No scored pixel in the interior (an image under 2·radius + 1 px, or a mask hugging the
  // border): the border pixels are all there is, so score them rather than refuse.
  if (total.interior_count == 0) return total.all / double(total.all_count);
  return total.interior / double(total.interior_count);
}

}  // namespace aolab
