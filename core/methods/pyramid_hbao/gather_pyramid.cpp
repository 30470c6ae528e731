#include "core/methods/pyramid_hbao/gather_pyramid.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/base/check.h"
#include "core/base/parallel.h"
#include "core/methods/pyramid_hbao/depth_pyramid.h"

namespace aolab {

GatherPyramid::GatherPyramid(const GBuffer& g, int reduction, int levels, int threads) {
  g.validate();
  const int w = g.width(), h = g.height();
  // DepthPyramid's shape and its checks.
  const int full = DepthPyramid::full_levels(w, h, reduction);
  if (levels < 0) throw_invalid("levels", "must be >= 0 (0 = down to 1x1)", levels);
  const int count = levels == 0 ? full : std::min(levels, full);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  levels_.resize(std::size_t(count));
  storage_.resize(std::size_t(count));

  // Level 0: the depth, background (by the G-buffer's rule, and anything not finite and
  // positive, as DepthPyramid) as NaN.
  {
    Arrays& a = storage_[0];
    GatherPyramidLevel& base = levels_[0];
    base.width = w, base.height = h, base.stride = w + 2, base.scale = 1;
    a.depth.assign(std::size_t(w + 2) * std::size_t(h + 2), nan);
    parallel_for_rows(h, threads, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < w; ++x) {
          const float d = g.depth(x, y);
          a.depth[base.at(x, y)] = g.valid(x, y) && std::isfinite(d) && d > 0.0f ? d : nan;
        }
    });
    base.depth = a.depth.data();
  }

  const int k = reduction;
  for (int l = 1; l < count; ++l) {
    const GatherPyramidLevel& fine = levels_[std::size_t(l - 1)];
    GatherPyramidLevel& coarse = levels_[std::size_t(l)];
    Arrays& a = storage_[std::size_t(l)];
    coarse.width = (fine.width + k - 1) / k;
    coarse.height = (fine.height + k - 1) / k;
    coarse.stride = coarse.width + 2;
    coarse.scale = fine.scale * k;
    const std::size_t n = std::size_t(coarse.stride) * std::size_t(coarse.height + 2);
    a.depth.assign(n, nan), a.cx.assign(n, 0.0f), a.cy.assign(n, 0.0f);
    const double scale = coarse.scale;
    parallel_for_rows(coarse.height, threads, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < coarse.width; ++x) {
          // DepthPyramid::build: the plain mean of the children that hold geometry, summed in
          // double in the same order (rows, then columns) and rounded once.
          double sum_d = 0, sum_x = 0, sum_y = 0;
          int count_children = 0;
          const int cy_end = std::min(fine.height, (y + 1) * k);
          const int cx_end = std::min(fine.width, (x + 1) * k);
          for (int cy = y * k; cy < cy_end; ++cy)
            for (int cx = x * k; cx < cx_end; ++cx) {
              const std::size_t i = fine.at(cx, cy);
              const float d = fine.depth[i];
              if (!(d == d)) continue;  // background
              sum_d += std::abs(d);
              if (fine.cx) {
                sum_x += fine.cx[i], sum_y += fine.cy[i];
              } else {
                sum_x += float(cx) + 0.5f, sum_y += float(cy) + 0.5f;
              }
              ++count_children;
            }
          const std::size_t i = coarse.at(x, y);
          const float centre_x = float(scale * (x + 0.5)), centre_y = float(scale * (y + 0.5));
          if (count_children == 0) {
            a.depth[i] = nan, a.cx[i] = centre_x, a.cy[i] = centre_y;
          } else {
            const float d = float(sum_d / count_children);
            a.cx[i] = float(sum_x / count_children), a.cy[i] = float(sum_y / count_children);
            a.depth[i] = a.cx[i] == centre_x && a.cy[i] == centre_y ? d : -d;
          }
        }
    });
    coarse.depth = a.depth.data(), coarse.cx = a.cx.data(), coarse.cy = a.cy.data();
  }
}

}  // namespace aolab
