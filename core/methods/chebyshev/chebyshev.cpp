#include "core/methods/chebyshev/chebyshev.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <mutex>

#include "core/base/check.h"
#include "core/base/parallel.h"
#include "core/methods/chebyshev/chebyshev_shared.h"

namespace aolab {

namespace {

using chebyshev_detail::Frame;
using chebyshev_detail::FrameVector;
using chebyshev_detail::kFramePadding;
using chebyshev_detail::Level;
using chebyshev_detail::LevelRows;
using chebyshev_detail::Plan;

// Horizontal pass of one row for half-width r (§III: "two mutually perpendicular blur
// filters"), for the columns [lo, hi]: for each column x, over the symmetric segment
// [x − rx, x + rx] with rx = min(r, x, w − 1 − x), the count n, s1 = Σ(f − c) and
// s2 = Σ(f − c)² about a reference c in the segment: the pixel itself, or if it is background
// the nearest valid pixel (left on ties), or 0 if the segment has none (n = 0). Sums of
// offsets, never of raw depths: they keep their precision at any depth.
void horizontal_row(const Frame& f, int y, int r, int lo, int hi, float* hn, float* hs1, float* hs2,
                    float* hc, std::vector<int>& left, std::vector<int>& right) {
  const int w = f.w;
  const float* d = f.depth.data() + std::size_t(y) * w;
  const float* m = f.weight.data() + std::size_t(y) * w;
  for (int x = 0, last = -1; x < w; ++x) left[x] = last = m[x] != 0.0f ? x : last;
  for (int x = w - 1, last = -1; x >= 0; --x) right[x] = last = m[x] != 0.0f ? x : last;
  for (int x = lo; x <= hi; ++x) {
    const int rx = std::min({r, x, w - 1 - x});
    const int dl = left[x] >= 0 ? x - left[x] : w, dr = right[x] >= 0 ? right[x] - x : w;
    const int nearest = dl <= dr ? left[x] : right[x];
    hc[x] = std::min(dl, dr) <= rx ? d[nearest] : 0.0f;
    hn[x] = hs1[x] = hs2[x] = 0.0f;
  }
  // Interior columns (rx = r): taps outer, columns inner, so the columns vectorise while each
  // column still sums its taps in the order −r … r.
  const int x0 = std::max(r, lo), x1 = std::min(w - r, hi + 1);  // [x0, x1)
  for (int i = -r; i <= r && x0 < x1; ++i) {
    for (int x = x0; x < x1; ++x) {
      const float wi = m[x + i];
      const float diff = wi * (d[x + i] - hc[x]);
      hn[x] += wi;
      hs1[x] += diff;
      hs2[x] += diff * diff;
    }
  }
  // Columns near the image border, same order of taps.
  for (int x = lo; x <= hi; ++x) {
    if (x >= x0 && x < x1) continue;
    const int rx = std::min({r, x, w - 1 - x});
    for (int i = -rx; i <= rx; ++i) {
      const float wi = m[x + i];
      const float diff = wi * (d[x + i] - hc[x]);
      hn[x] += wi;
      hs1[x] += diff;
      hs2[x] += diff * diff;
    }
  }
}

// The quantised half-widths: 0 … kChebyshevExactLevels, then kChebyshevLevelsPerOctave per
// octave up to the largest setting (1024).
const std::vector<int>& level_table() {
  static const std::vector<int> table = [] {
    std::vector<int> t;
    for (int r = 0; r <= kChebyshevExactLevels; ++r) t.push_back(r);
    for (int i = 1;; ++i) {
      const int r = int(
          std::lround(kChebyshevExactLevels * std::exp2(double(i) / kChebyshevLevelsPerOctave)));
      t.push_back(r);
      if (r >= 1024) break;
    }
    return t;
  }();
  return table;
}

// Chessboard distance of every pixel to the nearest background pixel (background: 0; none:
// a large value), exact, in two separable passes that run in parallel: per column the
// distance v to the nearest background pixel of the column, then per row
// D(x) = min over x' of max(|x − x'|, v(x')), the lower envelope of those functions by the
// linear-time algorithm of Meijster, Roerdink and Hesselink, "A General Algorithm for
// Computing Distance Transforms in Linear Time" (2000), §4 with its L∞ f and Sep. The window
// of half-width r around a pixel holds no background iff r < distance.
FrameVector<int> background_distance(const Frame& f, int threads) {
  const int w = f.w, h = f.h, far = 1 << 30;
  FrameVector<int> dist(std::size_t(w) * h);
  // Columns, in blocks of 64 so that a row's part of a block is one contiguous run.
  constexpr int kBlock = 64;
  parallel_for_rows(
      (w + kBlock - 1) / kBlock, threads,
      [&](int b0, int b1) {
        const int xa = b0 * kBlock, xb = std::min(w, b1 * kBlock);
        for (int y = 0; y < h; ++y)
          for (int x = xa; x < xb; ++x) {
            const std::size_t i = std::size_t(y) * w + x;
            dist[i] = f.weight[i] == 0.0f ? 0 : y > 0 ? std::min(far, dist[i - w] + 1) : far;
          }
        for (int y = h - 2; y >= 0; --y)
          for (int x = xa; x < xb; ++x) {
            const std::size_t i = std::size_t(y) * w + x;
            dist[i] = std::min(dist[i], dist[i + w] + 1);
          }
      },
      nullptr, 1);
  // Rows: the lower envelope of f_i(x) = max(|x − i|, v(i)) over the columns i.
  parallel_for_rows(h, threads, [&](int y0, int y1) {
    std::vector<int> v(w), s(w), t(w);
    auto fn = [&](int x, int i) { return std::max(std::abs(x - i), v[i]); };
    auto sep = [&](int i, int u) {  // the first x at which f_u is below f_i (i < u)
      return v[i] <= v[u] ? std::max(i + v[u], (i + u) / 2) : std::min(u - v[i], (i + u) / 2);
    };
    for (int y = y0; y < y1; ++y) {
      int* row = dist.data() + std::size_t(y) * w;
      std::copy(row, row + w, v.begin());
      int q = 0;
      s[0] = t[0] = 0;
      for (int u = 1; u < w; ++u) {
        while (q >= 0 && fn(t[q], s[q]) > fn(t[q], u)) --q;
        if (q < 0) {
          q = 0, s[0] = u;
        } else {
          const int start = 1 + sep(s[q], u);
          if (start < w) ++q, s[q] = u, t[q] = start;
        }
      }
      for (int u = w - 1; u >= 0; --u) {
        row[u] = fn(u, s[q]);
        if (u == t[q]) --q;
      }
    }
  });
  return dist;
}

struct Buffers {
  Buffer<float> n, s1, s2, c;  // the horizontal pass, w·h each
};

// How window sizes relate: the vertical half-width of a window is R·fy/d = rh·fy/fx when
// adaptive, square otherwise.
struct WindowShape {
  bool adaptive;
  double aspect;  // fy / fx
  int max_kernel_radius;
  int vertical(int rh) const {
    return adaptive ? int(std::min<double>(std::round(rh * aspect), max_kernel_radius)) : rh;
  }
};

// The frame, with the window half-width of every pixel in `level` (until assign_levels
// replaces it by the level's index): R·fx/d (k ∝ 1/d, §III) quantised, or the fixed one; 0 for
// background.
Frame make_frame(const GBuffer& g, const ChebyshevSettings& s, const WindowShape& shape,
                 int threads) {
  const int w = g.width(), h = g.height();
  const std::size_t pixels = std::size_t(w) * h;
  Frame f{w, h, FrameVector<float>(pixels + kFramePadding),
          FrameVector<float>(pixels + kFramePadding), FrameVector<int>(pixels + kFramePadding)};
  for (std::size_t i = pixels; i < pixels + kFramePadding; ++i)
    f.depth[i] = f.weight[i] = 0.0f, f.level[i] = -1;
  parallel_for_rows(h, threads, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t i = std::size_t(y) * w + x;
        const bool valid = g.valid(x, y);
        f.depth[i] = valid ? g.depth(x, y) : 0.0f;
        f.weight[i] = valid ? 1.0f : 0.0f;
        f.level[i] = !valid ? 0
                     : shape.adaptive
                         ? chebyshev_quantised_radius(
                               double(s.radius) * g.camera.fx / g.depth(x, y), s.max_kernel_radius)
                         : s.kernel_radius;
      }
  });
  return f;
}

// Windows shrink to a level that holds no background pixel (symmetric, so a plane stays
// exactly 1 up to its silhouette). A frame without background has nothing to shrink.
void shrink_at_background(Frame& f, const WindowShape& shape, int max_r, int threads) {
  const std::size_t pixels = std::size_t(f.w) * f.h;
  if (std::find(f.weight.begin(), f.weight.begin() + std::ptrdiff_t(pixels), 0.0f) ==
      f.weight.begin() + std::ptrdiff_t(pixels))
    return;
  const FrameVector<int> dist = background_distance(f, threads);
  std::vector<int> vertical(std::size_t(max_r) + 1);
  for (int r = 0; r <= max_r; ++r) vertical[r] = shape.vertical(r);
  parallel_for_rows(f.h, threads, [&](int y0, int y1) {
    for (std::size_t i = std::size_t(y0) * f.w; i < std::size_t(y1) * f.w; ++i) {
      int r = f.level[i];
      while (r > 0 && std::max(r, vertical[r]) >= dist[i])
        r = chebyshev_level_below(std::min(r - 1, dist[i] - 1));
      f.level[i] = r;
    }
  });
}

// The distinct half-widths (levels) in increasing order; replaces every pixel's half-width
// by its level's index (−1: none).
std::vector<Level> assign_levels(Frame& f, const WindowShape& shape, int max_r, int threads) {
  std::vector<int> index_of(std::size_t(max_r) + 1, -1);
  std::mutex merge;
  parallel_for_rows(f.h, threads, [&](int y0, int y1) {
    std::vector<char> used(std::size_t(max_r) + 1, 0);
    for (std::size_t i = std::size_t(y0) * f.w; i < std::size_t(y1) * f.w; ++i)
      used[f.level[i]] = 1;
    const std::lock_guard<std::mutex> lock(merge);
    for (int r = 0; r <= max_r; ++r)
      if (used[r]) index_of[r] = 0;
  });
  std::vector<Level> levels;
  for (int r = 1; r <= max_r; ++r) {
    if (index_of[r] < 0) continue;
    index_of[r] = int(levels.size());
    levels.push_back({r, shape.vertical(r)});
  }
  parallel_for_rows(f.h, threads, [&](int y0, int y1) {
    for (std::size_t i = std::size_t(y0) * f.w; i < std::size_t(y1) * f.w; ++i)
      f.level[i] = f.level[i] > 0 ? index_of[f.level[i]] : -1;
  });
  return levels;
}

// The rows and columns of every level's passes; rows in parallel, then levels in parallel.
std::vector<LevelRows> level_rows(const Frame& f, const std::vector<Level>& levels, int threads) {
  const int w = f.w, h = f.h;
  std::vector<LevelRows> rows(levels.size());
  for (LevelRows& r : rows) r.span_lo.assign(h, w), r.span_hi.assign(h, -1);
  // A row's spans are found in local arrays and stored once per level: stored per pixel,
  // the two threads' 4-row bands wrote the same cache lines of span_lo/span_hi (16 rows to
  // a line) for every pixel, and a second thread made the plan slower, not faster.
  parallel_for_rows(h, threads, [&](int y0, int y1) {
    std::vector<int> lo(levels.size()), hi(levels.size());
    for (int y = y0; y < y1; ++y) {
      std::fill(lo.begin(), lo.end(), w);
      std::fill(hi.begin(), hi.end(), -1);
      const int* level = f.level.data() + std::size_t(y) * w;
      for (int x = 0; x < w; ++x) {
        const int l = level[x];
        if (l < 0) continue;
        lo[l] = std::min(lo[l], x);
        hi[l] = std::max(hi[l], x);
      }
      for (std::size_t l = 0; l < levels.size(); ++l)
        rows[l].span_lo[y] = lo[l], rows[l].span_hi[y] = hi[l];
    }
  });
  parallel_for_rows(
      int(levels.size()), threads,
      [&](int l0, int l1) {
        for (int l = l0; l < l1; ++l) {
          LevelRows& r = rows[l];
          r.need_lo.assign(h, w), r.need_hi.assign(h, -1);
          for (int y = 0; y < h; ++y) {
            if (r.span_hi[y] < 0) continue;
            r.receiver_rows.push_back(y);
            const int ry = std::min({levels[l].rv, y, h - 1 - y});
            for (int j = y - ry; j <= y + ry; ++j) {
              r.need_lo[j] = std::min(r.need_lo[j], r.span_lo[y]);
              r.need_hi[j] = std::max(r.need_hi[j], r.span_hi[y]);
            }
          }
          for (int y = 0; y < h; ++y)
            if (r.need_hi[y] >= 0) r.pass_rows.push_back(y);
        }
      },
      nullptr, 1);
  return rows;
}

// The horizontal pass of one level over the rows and columns it needs.
void horizontal_pass(const Frame& f, const Level& lv, const LevelRows& rows, Buffers& b,
                     int threads, Progress* progress) {
  const int w = f.w;
  parallel_for_rows(
      int(rows.pass_rows.size()), threads,
      [&](int i0, int i1) {
        std::vector<int> left(w), right(w);
        for (int i = i0; i < i1; ++i) {
          const int y = rows.pass_rows[i];
          const std::size_t o = std::size_t(y) * w;
          horizontal_row(f, y, lv.rh, rows.need_lo[y], rows.need_hi[y], b.n.data() + o,
                         b.s1.data() + o, b.s2.data() + o, b.c.data() + o, left, right);
        }
      },
      progress);
}

// Vertical pass of row y for the receivers of level l in columns [xa, xb): shift each row's
// sums from its reference c to the receiver's depth d,
//   Σ(f − d) = s1 + n·δ,  Σ(f − d)² = s2 + 2δ·s1 + n·δ²,  δ = c − d,
// exact identities evaluated in double; c lies in the receiver's window, so every term is
// bounded by the window's own Σ(f − d)² (no cancellation beyond that sum's rounding).
void vertical_row(const Frame& f, int l, int rv, int y, int xa, int xb, const Buffers& b,
                  Image& out, std::vector<double>& sn, std::vector<double>& s1,
                  std::vector<double>& s2) {
  const int w = f.w, h = f.h;
  const int span = xb - xa;
  sn.assign(span, 0.0), s1.assign(span, 0.0), s2.assign(span, 0.0);
  const float* dr = f.depth.data() + std::size_t(y) * w + xa;
  const int ry = std::min({rv, y, h - 1 - y});
  for (int j = -ry; j <= ry; ++j) {
    const std::size_t o = std::size_t(y + j) * w + xa;
    const float *hn = b.n.data() + o, *h1 = b.s1.data() + o, *h2 = b.s2.data() + o,
                *hc = b.c.data() + o;
    for (int x = 0; x < span; ++x) {
      const double n = hn[x], a = h1[x];
      const double delta = double(hc[x]) - double(dr[x]);
      sn[x] += n;
      s1[x] += a + n * delta;
      s2[x] += double(h2[x]) + delta * (2.0 * a + n * delta);
    }
  }
  const int* level = f.level.data() + std::size_t(y) * w + xa;
  for (int x = 0; x < span; ++x) {
    if (level[x] != l) continue;
    const double m1 = s1[x] / sn[x], m2 = s2[x] / sn[x];
    out(xa + x, y, 0) = float(sn[x]);
    out(xa + x, y, 1) = float(-m1);                          // λ = d − μ
    out(xa + x, y, 2) = float(std::max(0.0, m2 - m1 * m1));  // σ² (§III)
  }
}

void vertical_pass(const Frame& f, int l, const Level& lv, const LevelRows& rows, const Buffers& b,
                   Image& out, int threads, Progress* progress) {
  const std::vector<int>& recv = rows.receiver_rows;
  parallel_for_rows(
      int(recv.size()), threads,
      [&](int i0, int i1) {
        std::vector<double> sn, s1, s2;
        for (int i = i0; i < i1; ++i) {
          const int y = recv[i];
          vertical_row(f, l, lv.rv, y, rows.span_lo[y], rows.span_hi[y] + 1, b, out, sn, s1, s2);
        }
      },
      progress);
}

}  // namespace

int chebyshev_quantised_radius(double r, int cap) {
  if (!(r >= 0.5) || cap <= 0) return 0;
  if (r >= double(cap)) return cap;
  if (r < kChebyshevExactLevels + 0.5) return std::min(cap, int(std::lround(r)));
  const std::vector<int>& t = level_table();
  const auto hi = std::upper_bound(t.begin(), t.end(), r);  // r < 1024 here
  const int above = *hi, below = *(hi - 1);
  return std::min(cap, r / below <= above / r ? below : above);  // the nearer in ratio
}

int chebyshev_level_below(int r) {
  const std::vector<int>& t = level_table();
  if (r >= t.back()) return t.back();
  return *(std::upper_bound(t.begin(), t.end(), std::max(r, 0)) - 1);
}

float chebyshev_visibility(float gap, float variance, const ChebyshevSettings& s) {
  const double var = std::max(0.0, double(variance));
  double lambda = gap;
  // Rounding of the window mean is not occlusion (kChebyshevMeanTolerance).
  if (std::abs(lambda) <= kChebyshevMeanTolerance * std::sqrt(var + lambda * lambda)) lambda = 0;
  // Eq. 3 (§III-B): only a receiver behind the mean is occluded; eq. 2: either side.
  const double g = s.ignore_unoccluded ? std::max(lambda, 0.0) : std::abs(lambda);
  if (!(g > 0.0)) return 1.0f;  // includes §III-A's σ² = 0, d = μ: P = ε/ε = 1
  const double radius = s.radius;
  const double biased = var + double(s.variance_bias) * radius * radius;  // σ² + ε (§III-A)
  const double p = biased / (biased + g * g);                             // eq. 2 / eq. 3
  if (!s.range_check) return float(std::clamp(p, 0.0, 1.0));
  // §III-C: occluders far in front of the receiver (mean gap beyond R) fade out.
  const double t = std::min(1.0, radius / g);
  const double fade = t * t * (3.0 - 2.0 * t);
  return float(std::clamp(1.0 - (1.0 - p) * fade, 0.0, 1.0));
}

namespace chebyshev_detail {

Plan make_plan(const GBuffer& g, const ChebyshevSettings& s, int threads) {
  const WindowShape shape{s.kernel_mode == int(ChebyshevKernel::Adaptive),
                          double(g.camera.fy) / g.camera.fx, s.max_kernel_radius};
  Plan plan;
  plan.frame = make_frame(g, s, shape, threads);
  const int max_r = std::max(s.kernel_radius, s.max_kernel_radius);
  if (s.shrink_at_background) shrink_at_background(plan.frame, shape, max_r, threads);
  plan.levels = assign_levels(plan.frame, shape, max_r, threads);
  plan.rows = level_rows(plan.frame, plan.levels, threads);
  for (const LevelRows& r : plan.rows)
    plan.total_rows += std::int64_t(r.pass_rows.size() + r.receiver_rows.size());
  return plan;
}

}  // namespace chebyshev_detail

namespace {

// The moments (3 channels) by the scalar passes, or the visibility (1 channel) from them.
Image scalar_moments(const Plan& plan, int threads, Progress* progress) {
  const Frame& f = plan.frame;
  const int w = f.w, h = f.h;
  const std::size_t pixels = std::size_t(w) * h;
  Image out(w, h, 3, 0.0f);
  // Pixels without a window (half-width 0): the window is the pixel itself.
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (f.weight[std::size_t(y) * w + x] != 0.0f && f.level[std::size_t(y) * w + x] < 0)
        out(x, y, 0) = 1.0f;

  const std::size_t buffer = plan.levels.empty() ? 0 : pixels;
  Buffers b{Buffer<float>(buffer), Buffer<float>(buffer), Buffer<float>(buffer),
            Buffer<float>(buffer)};
  for (int l = 0; l < int(plan.levels.size()); ++l) {
    horizontal_pass(f, plan.levels[l], plan.rows[l], b, threads, progress);
    vertical_pass(f, l, plan.levels[l], plan.rows[l], b, out, threads, progress);
  }
  return out;
}

// Validates, plans and runs the kernel `options` names: the moments if `want_moments`, else
// the visibility.
Image run(const GBuffer& g, const ChebyshevSettings& s, const RunOptions& options,
          bool want_moments) {
  g.validate();
  validate_settings(s, kChebyshevFields);
  const int w = g.width(), h = g.height();
  const int threads = resolve_threads(options.threads);
  const Plan plan = chebyshev_detail::make_plan(g, s, threads);
  if (options.progress) options.progress->total += plan.total_rows;
  if (plan.total_rows == 0)  // no window anywhere: still one tick, and a chance to cancel
    parallel_for_rows(
        1, 1, [](int, int) {}, options.progress);

  if (options.kernel == Kernel::Simd) {
    Image out(w, h, want_moments ? 3 : 1, want_moments ? 0.0f : 1.0f);
    chebyshev_simd(plan, s, threads, options.progress, want_moments ? &out : nullptr,
                   want_moments ? nullptr : &out);
    return out;
  }
  Image moments = scalar_moments(plan, threads, options.progress);
  if (want_moments) return moments;
  Image out(w, h, 1, 1.0f);
  parallel_for_rows(h, threads, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w; ++x)
        if (moments(x, y, 0) > 0.0f)
          out(x, y) = chebyshev_visibility(moments(x, y, 1), moments(x, y, 2), s);
  });
  return out;
}

}  // namespace

Image chebyshev_moments(const GBuffer& g, const ChebyshevSettings& s, const RunOptions& options) {
  return run(g, s, options, true);
}

Image chebyshev(const GBuffer& g, const ChebyshevSettings& s, const RunOptions& options) {
  return run(g, s, options, false);
}

Method chebyshev_method() {
  Method m =
      registered_method("chebyshev", "Chebyshev ambient occlusion",
                        "Chan, Im 2021, Chebyshev Ambient Occlusion", kChebyshevFields, chebyshev);
  m.has_simd_kernel = true;
  return m;
}

}  // namespace aolab
