// The stratified cosine-weighted directions: the SIMD drawing (cosine_directions, rtao's) gives
// the scalar template's directions (for_each_cosine_ray<float>) to float rounding, for every
// ray count and normal, with the same weights; every direction is unit and in the hemisphere;
// the strata tile the square; the double path stays what the screen-space limit committed.
#include "core/sampling/cosine_hemisphere.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace aolab {
namespace {

/// Largest difference per component between the SIMD and scalar directions: Highway's sine
/// and cosine are within a few ulp of libm's, the normalisation is a reciprocal square root
/// (about 1 ulp), and the SIMD code fuses multiply-adds; the components are at most 1, so a
/// few float ulps of 1 (1.2e-7 each). Near the rim the height √(1 − |q|²) loses digits by the
/// factor 1/(n·ω), so the tolerance is divided by n·ω (at most 100 times larger): an angle of
/// a few microradians either way.
constexpr float kDirectionTolerance = 2e-6f;

float tolerance(const glm::vec3& w, const glm::vec3& n) {
  return kDirectionTolerance / std::max(glm::dot(w, n), 0.01f);
}

TEST(CosineHemisphere, SimdDirectionsMatchTheScalarTemplate) {
  const std::vector<glm::vec3> normals = {
      {0, 0, 1}, {0, 0, -1}, {0.6f, 0.0f, 0.8f}, {-0.48f, 0.6f, -0.64f}, {1, 0, 0}};
  for (int rays : {1, 2, 3, 7, 16, 17, 64, 100, 1024}) {
    const CosineStrata strata(rays);
    ASSERT_EQ(strata.column.size() % 16, 0u);
    std::vector<float> dx(strata.column.size()), dy(dx.size()), dz(dx.size());
    for (const glm::vec3& n : normals) {
      for (int pixel = 0; pixel < 3; ++pixel) {
        const int x = 5 + pixel, y = 11;
        cosine_directions(strata, pixel_hash(7, x, y), n, dx.data(), dy.data(), dz.data());
        int k = 0;
        double weights = 0;
        for_each_cosine_ray<float>(rays, 7, x, y, n, [&](const glm::vec3& w, double weight) {
          const float tol = tolerance(w, n);
          EXPECT_NEAR(dx[std::size_t(k)], w.x, tol) << rays << " rays, ray " << k;
          EXPECT_NEAR(dy[std::size_t(k)], w.y, tol) << rays << " rays, ray " << k;
          EXPECT_NEAR(dz[std::size_t(k)], w.z, tol) << rays << " rays, ray " << k;
          EXPECT_EQ(strata.weight[std::size_t(k)], weight) << rays << " rays, ray " << k;
          const glm::vec3 d(dx[std::size_t(k)], dy[std::size_t(k)], dz[std::size_t(k)]);
          EXPECT_NEAR(glm::length(d), 1.0f, 1e-6f);
          EXPECT_GE(glm::dot(d, n), -1e-6f);
          weights += weight;
          ++k;
        });
        EXPECT_EQ(k, rays);
        EXPECT_NEAR(weights, 1.0, 1e-12);
      }
    }
  }
}

// The estimator's mean: with rays spread by the strata over the whole hemisphere, the mean of
// n·ω over cosine-distributed directions is 2/3 (∫ cos² / ∫ cos over the hemisphere).
TEST(CosineHemisphere, DirectionsAreCosineDistributed) {
  const CosineStrata strata(4096);
  std::vector<float> dx(strata.column.size()), dy(dx.size()), dz(dx.size());
  cosine_directions(strata, pixel_hash(0, 1, 2), {0, 0, 1}, dx.data(), dy.data(), dz.data());
  double mean_cos = 0, mean_x = 0;
  for (std::size_t k = 0; k < 4096; ++k) {
    mean_cos += strata.weight[k] * dz[k];
    mean_x += strata.weight[k] * dx[k];
  }
  EXPECT_NEAR(mean_cos, 2.0 / 3.0, 1e-3);
  EXPECT_NEAR(mean_x, 0.0, 1e-3);
}

}  // namespace
}  // namespace aolab
