// The void-and-cluster blue noise of Pyramid HBAO (§3.5): a permutation of the ranks, with
// little energy at low spatial frequencies, cached once.
#include "core/sampling/blue_noise.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <numeric>
#include <thread>
#include <vector>

#include "core/sampling/random.h"
#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

constexpr int kN = kBlueNoiseSize;

std::vector<std::uint32_t> cached_ranks() {
  const auto& r = blue_noise_ranks();
  return {r.begin(), r.end()};
}

// Mean power of the 2-D DFT of (value − mean) over the frequencies with 0 < |f| <= radius
// (cycles per kN pixels), divided by the mean power over all non-zero frequencies. Any
// permutation of 0 … kN²−1 has the same total power (Parseval), so white noise gives ≈ 1 at
// every radius and blue noise ≪ 1 at low radii.
double low_frequency_power_ratio(const std::vector<std::uint32_t>& ranks, double radius) {
  const double mean = (kN * kN - 1) / 2.0;
  double low = 0, all = 0;
  int n_low = 0, n_all = 0;
  for (int v = 0; v < kN; ++v)
    for (int u = 0; u < kN; ++u) {
      if (u == 0 && v == 0) continue;
      std::complex<double> sum = 0;
      for (int y = 0; y < kN; ++y)
        for (int x = 0; x < kN; ++x) {
          const double phase = -2.0 * std::numbers::pi * double(u * x + v * y) / kN;
          sum += (double(ranks[std::size_t(y) * kN + x]) - mean) *
                 std::complex<double>(std::cos(phase), std::sin(phase));
        }
      const double power = std::norm(sum);
      const int fu = std::min(u, kN - u), fv = std::min(v, kN - v);
      all += power, ++n_all;
      if (std::hypot(fu, fv) <= radius) low += power, ++n_low;
    }
  return (low / n_low) / (all / n_all);
}

TEST(BlueNoise, HoldsEveryRankExactlyOnce) {
  std::vector<std::uint32_t> r = cached_ranks();
  ASSERT_EQ(r.size(), std::size_t(kN * kN));
  std::sort(r.begin(), r.end());
  for (std::uint32_t i = 0; i < r.size(); ++i) ASSERT_EQ(r[i], i);
}

// The blue-noise property (Ulichney 1993): the power spectrum is low at low frequencies.
// White noise (a random permutation) has a ratio near 1; the bounds leave a wide margin on
// both (measured: blue 0.0003, white 0.89 at |f| <= 4).
TEST(BlueNoise, LowFrequencyPowerIsFarBelowWhiteNoise) {
  const double blue = low_frequency_power_ratio(cached_ranks(), 4.0);
  std::vector<std::uint32_t> white(kN * kN);
  std::iota(white.begin(), white.end(), 0u);
  for (std::size_t i = white.size() - 1; i > 0; --i)  // Fisher-Yates with the project's hash
    std::swap(white[i], white[pcg_hash(std::uint32_t(i) ^ 0xB5297A4Du) % (i + 1)]);
  const double white_ratio = low_frequency_power_ratio(white, 4.0);
  EXPECT_LT(blue, 0.05) << "white noise gives " << white_ratio;
  EXPECT_GT(white_ratio, 0.5);
}

// Every threshold of a void-and-cluster array is an evenly spread point set: the lowest 5 %
// of the ranks have no two points closer than 3 pixels (toroidally; a homogeneous pattern of
// that density has a spacing of 4.5) and the lowest 10 % none closer than 2. A random
// permutation of the same density has adjacent points at both thresholds (measured).
TEST(BlueNoise, ThresholdsAreEvenlySpread) {
  const std::vector<std::uint32_t> r = cached_ranks();
  for (const auto& [count, min_distance2] : {std::pair{51u, 9}, std::pair{102u, 4}}) {
    std::vector<std::pair<int, int>> points;
    for (int i = 0; i < kN * kN; ++i)
      if (r[i] < count) points.emplace_back(i % kN, i / kN);
    int closest = kN * kN;
    for (std::size_t a = 0; a < points.size(); ++a)
      for (std::size_t b = a + 1; b < points.size(); ++b) {
        int dx = std::abs(points[a].first - points[b].first);
        int dy = std::abs(points[a].second - points[b].second);
        dx = std::min(dx, kN - dx), dy = std::min(dy, kN - dy);
        closest = std::min(closest, dx * dx + dy * dy);
      }
    EXPECT_GE(closest, min_distance2) << "lowest " << count << " ranks";
  }
}

TEST(BlueNoise, IsCachedOnceAndDeterministic) {
  const auto* first = &blue_noise_ranks();
  std::vector<const void*> seen(4);
  std::vector<std::thread> pool;
  for (auto& s : seen) pool.emplace_back([&s] { s = &blue_noise_ranks(); });
  for (auto& t : pool) t.join();
  for (const void* s : seen) EXPECT_EQ(s, first);
  EXPECT_EQ(cached_ranks(), void_and_cluster(kN, kBlueNoiseSigma, kBlueNoiseSeed));
  EXPECT_NE(cached_ranks(), void_and_cluster(kN, kBlueNoiseSigma, kBlueNoiseSeed + 1));
}

TEST(BlueNoise, ValueTilesThePlane) {
  const auto& r = blue_noise_ranks();
  for (int y = -40; y < 40; y += 7)
    for (int x = -40; x < 40; x += 5) {
      const float v = blue_noise_value(r, x, y);
      EXPECT_GT(v, 0.0f);
      EXPECT_LT(v, 1.0f);
      EXPECT_EQ(v, blue_noise_value(r, x + kN, y));
      EXPECT_EQ(v, blue_noise_value(r, x, y - 3 * kN));
    }
  EXPECT_EQ(blue_noise_value(r, 0, 0), (float(r[0]) + 0.5f) / 1024.0f);
}

TEST(BlueNoise, RejectsBadArguments) {
  using testing::invalid_argument_message;
  EXPECT_NE(invalid_argument_message([] { void_and_cluster(1, 1.5, 0); }).find("size"),
            std::string::npos);
  EXPECT_NE(invalid_argument_message([] { void_and_cluster(8, 0.0, 0); }).find("sigma"),
            std::string::npos);
  const auto small = void_and_cluster(8, 1.5, 3);
  std::vector<std::uint32_t> sorted(small);
  std::sort(sorted.begin(), sorted.end());
  for (std::uint32_t i = 0; i < sorted.size(); ++i) EXPECT_EQ(sorted[i], i);
}

}  // namespace
}  // namespace aolab
