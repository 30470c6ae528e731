#include "core/scoring/metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/base/check.h"
#include "core/base/parallel.h"
#include "core/scoring/ssim.h"

namespace aolab {

namespace {

void require_one_channel(const std::string& name, const ConstImageView& image) {
  if (image.channels != 1) throw_invalid(name, "must have 1 channel", image.channels);
}

// Sums of one row of scored pixels. Kept per row and added row by row afterwards, so the
// order of additions — and hence the bits — never depend on how rows were shared out.
struct RowSums {
  double abs_error = 0;
  double squared_error = 0;
  double error = 0;
  std::int64_t count = 0;
};

}  // namespace

void require_finite(const std::string& name, ConstImageView image, ConstImageView mask,
                    int threads) {
  require_one_channel(name, image);
  const bool masked = !mask.empty();
  if (masked) {
    require_same_size(name, image, "mask", mask);
    require_one_channel("mask", mask);
  }
  // First non-finite column of each row, or −1: the rows are searched in parallel, the
  // reported pixel is still the first in row-major order.
  std::vector<int> first_bad(std::size_t(std::max(image.height, 0)), -1);
  parallel_for_rows(image.height, threads, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      const float* row = image.row(y);
      const float* mask_row = masked ? mask.row(y) : nullptr;
      for (int x = 0; x < image.width; ++x) {
        if (mask_row && mask_row[x] == 0.0f) continue;
        if (!std::isfinite(row[x])) {
          first_bad[std::size_t(y)] = x;
          break;
        }
      }
    }
  });
  for (int y = 0; y < image.height; ++y) {
    const int x = first_bad[std::size_t(y)];
    if (x >= 0)
      throw_invalid(name,
                    "must be finite on every scored pixel; the first non-finite one is (x=" +
                        std::to_string(x) + ", y=" + std::to_string(y) + ")",
                    image(x, y));
  }
}

void require_comparable(const std::string& name_a, ConstImageView a, const std::string& name_b,
                        ConstImageView b, ConstImageView mask, int threads) {
  require_one_channel(name_a, a);
  if (a.empty())
    throw_invalid(name_a, "must not be empty",
                  std::to_string(a.width) + "x" + std::to_string(a.height));
  require_same_size(name_a, a, name_b, b);
  require_one_channel(name_b, b);
  if (!mask.empty()) {
    require_same_size(name_a, a, "mask", mask);
    require_one_channel("mask", mask);
  }
  require_finite(name_a, a, mask, threads);
  require_finite(name_b, b, mask, threads);
}

Metrics compute_metrics(ConstImageView ao, ConstImageView reference, ConstImageView mask,
                        int threads) {
  require_comparable("ao", ao, "reference", reference, mask, threads);
  const bool masked = !mask.empty();

  std::vector<RowSums> rows(std::size_t(ao.height));
  parallel_for_rows(ao.height, threads, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      const float* a = ao.row(y);
      const float* r = reference.row(y);
      const float* m = masked ? mask.row(y) : nullptr;
      RowSums s;
      for (int x = 0; x < ao.width; ++x) {
        if (m && m[x] == 0.0f) continue;
        // Differences in double: float differences of nearly equal values would lose the
        // low bits that a small MSE is made of.
        const double d = double(a[x]) - double(r[x]);
        s.abs_error += std::abs(d);
        s.squared_error += d * d;
        s.error += d;
        ++s.count;
      }
      rows[std::size_t(y)] = s;
    }
  });
  RowSums total;
  for (const RowSums& s : rows) {
    total.abs_error += s.abs_error;
    total.squared_error += s.squared_error;
    total.error += s.error;
    total.count += s.count;
  }
  if (total.count == 0) throw_invalid("mask", "must select at least one pixel", 0);

  Metrics m;
  const double n = double(total.count);
  const double mse = total.squared_error / n;
  m.count = total.count;
  m.mae = total.abs_error / n;
  m.rmse = std::sqrt(mse);
  // Data range 1 (AO in [0, 1]): PSNR = 10 log10(1² / MSE); exact agreement is +infinity
  // rather than a division by zero.
  m.psnr = mse > 0 ? 10.0 * std::log10(1.0 / mse) : std::numeric_limits<double>::infinity();
  m.bias = total.error / n;
  m.ssim = mean_ssim(ao, reference, mask, SsimSettings{}, threads);
  return m;
}

}  // namespace aolab
