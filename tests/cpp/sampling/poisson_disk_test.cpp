// The rotation-aware Poisson-disk sets of VAO++ §4.5 (core/sampling/poisson_disk.h).
#include "core/sampling/poisson_disk.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

constexpr int kSizes[] = {2, 4, 8, 16, 32};

double sum_of_distances(const std::vector<DiskPoint>& p, int begin, int end) {
  double s = 0;
  for (int j = begin; j < end; ++j)
    for (int i = 0; i < j; ++i) s += std::hypot(double(p[j].x) - p[i].x, double(p[j].y) - p[i].y);
  return s;
}

TEST(PoissonDisk, EveryRotationKeepsThePoissonRadius) {
  for (int n : kSizes) {
    const PoissonDiskSet& set = rotation_aware_poisson_disk(n);
    ASSERT_EQ(int(set.points.size()), n);
    for (const auto& p : set.points) EXPECT_LE(std::hypot(p.x, p.y), 1.0f + 1e-6f);
    // All 9n rotated points (a point's own rotations included) are >= r apart; the chosen
    // rotations only relabel points of the same 9n-point set.
    const float min_distance = min_rotated_distance(set.points);
    EXPECT_GE(min_distance, set.radius * (1.0f - 1e-5f)) << n;
    // Dart throwing reaches a radius near a dense packing: r >= 0.6 · 2 sqrt(1/(9n)).
    EXPECT_GE(set.radius, 0.6 * 2.0 * std::sqrt(1.0 / (9.0 * n))) << n;
    std::printf("n = %2d: Poisson radius %.4f, min distance over 9 rotations %.4f\n", n, set.radius,
                min_distance);
  }
}

TEST(PoissonDisk, DeterministicCachedAndZOrdered) {
  for (int n : kSizes) {
    const PoissonDiskSet a = generate_rotation_aware_poisson_disk(n);
    const PoissonDiskSet& b = rotation_aware_poisson_disk(n);
    EXPECT_EQ(&b, &rotation_aware_poisson_disk(n));
    ASSERT_EQ(a.points.size(), b.points.size());
    for (std::size_t i = 0; i < a.points.size(); ++i) {
      EXPECT_EQ(a.points[i].x, b.points[i].x);
      EXPECT_EQ(a.points[i].y, b.points[i].y);
      if (i > 0) {
        EXPECT_LE(morton_key(a.points[i - 1]), morton_key(a.points[i]));
      }
    }
  }
  EXPECT_EQ(morton_key({-1, -1}), 0u);
  EXPECT_EQ(morton_key({1, 1}), 0xFFFFFFFFu);
  EXPECT_EQ(morton_key({1, -1}), 0x55555555u);  // x on the even bits
}

// The largest sum of distances over the assignments of distinct rotations to the points
// (the first point's fixed: turning a whole set keeps its distances), by brute force.
double best_sum_brute_force(const std::vector<DiskPoint>& p, std::vector<DiskPoint>& chosen,
                            unsigned used) {
  const std::size_t j = chosen.size();
  if (j == p.size()) return sum_of_distances(chosen, 0, int(j));
  double best = -1;
  for (int k = 0; k < (j == 0 ? 1 : kPoissonRotations); ++k) {
    if (used & (1u << k)) continue;
    chosen.push_back(rotate_point(p[j], k));
    best = std::max(best, best_sum_brute_force(p, chosen, used | (1u << k)));
    chosen.pop_back();
  }
  return best;
}

TEST(PoissonDisk, ChosenRotationsMaximiseTheDistanceSum) {
  // §4.5: "we select the best permutation of rotated samples so that sum of their distances
  // from each other is maximal" — one group for n <= 8, checked against brute force.
  for (int n : {2, 4, 6}) {
    const PoissonDiskSet plain = generate_rotation_aware_poisson_disk(n, false);
    const PoissonDiskSet best = generate_rotation_aware_poisson_disk(n);
    std::vector<DiskPoint> chosen;
    const double expected = best_sum_brute_force(plain.points, chosen, 0u);
    EXPECT_NEAR(sum_of_distances(best.points, 0, n), expected, 1e-5) << n;
    EXPECT_GE(sum_of_distances(best.points, 0, n), sum_of_distances(plain.points, 0, n) - 1e-6);
  }
  // Larger sets: groups of 8, never worse than no permutation.
  for (int n : {16, 32}) {
    const PoissonDiskSet plain = generate_rotation_aware_poisson_disk(n, false);
    EXPECT_GE(sum_of_distances(rotation_aware_poisson_disk(n).points, 0, n),
              sum_of_distances(plain.points, 0, n) - 1e-6)
        << n;
  }
}

TEST(PoissonDisk, RejectsBadSizes) {
  EXPECT_NE(
      testing::invalid_argument_message([] { rotation_aware_poisson_disk(0); }).find("samples"),
      std::string::npos);
  EXPECT_NE(testing::invalid_argument_message([] {
              generate_rotation_aware_poisson_disk(65);
            }).find("samples"),
            std::string::npos);
}

}  // namespace
}  // namespace aolab
