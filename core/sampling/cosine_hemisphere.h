// Stratified cosine-weighted directions about a normal, shared by the estimators of Cycles'
// AO integral (the screen-space limit and the ray-traced rtao):
//   A(P) = (1/π) ∫_Ω V_R(P, ω) (n·ω) dω
// estimated with N directions of pdf (n·ω)/π, stratified on the unit square, mapped to the
// disk by Shirley & Chiu, "A Low Distortion Map Between Disk and Square" (JGT 1997), and
// lifted to the hemisphere (Malley's method):
//   Â = 1 − Σ_k w_k (1 − V_R(P, ω_k)),      Σ w_k = 1,  w_k = the area of ray k's stratum.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <numbers>
#include <type_traits>
#include <vector>

#include "core/sampling/random.h"

namespace aolab {

/// Shirley & Chiu's concentric map of [0, 1)² onto the unit disk: equal areas to equal areas
/// with little distortion, so the square's strata stay compact on the disk. In double (the
/// screen-space limit's committed images) or float (rtao: a third of the cost).
template <class Real>
glm::vec<2, Real> concentric_disk(Real u1, Real u2) {
  const Real a = Real(2) * u1 - Real(1), b = Real(2) * u2 - Real(1);
  if (a == Real(0) && b == Real(0)) return {Real(0), Real(0)};
  constexpr Real quarter = std::numbers::pi_v<Real> / Real(4);
  Real r, phi;
  if (std::abs(a) > std::abs(b))
    r = a, phi = quarter * (b / a);
  else
    r = b, phi = Real(2) * quarter - quarter * (a / b);
  return {r * std::cos(phi), r * std::sin(phi)};
}

/// A tangent frame (t, b) for the unit normal n: Duff et al., "Building an Orthonormal Basis,
/// Revisited" (JCGT 2017), listing 3; no branch on a threshold, so no seam.
template <class Real>
void tangent_frame(const glm::vec<3, Real>& n, glm::vec<3, Real>& t, glm::vec<3, Real>& b) {
  const Real sign = std::copysign(Real(1), n.z);
  const Real a = Real(-1) / (sign + n.z);
  const Real c = n.x * n.y * a;
  t = {Real(1) + sign * n.x * n.x * a, sign * c, -sign * n.x};
  b = {c, sign + n.y * n.y * a, -n.y};
}

/// Calls ray(ω, w) for the `rays` stratified cosine-weighted directions ω about the unit
/// normal n of pixel (x, y), w being the area of ω's stratum. ⌊√N⌋ columns of the unit square;
/// column c holds n_c rows, so that the N strata tile the square for any N; the weights sum to
/// 1, so summing only the blocked ones keeps an unoccluded pixel exactly 1. Ray k is jittered
/// in its stratum by pixel_random(seed, x, y, 2k) and (.., 2k + 1): the same directions for
/// the same pixel whatever the thread. `Real` is the arithmetic (double or float); the
/// weights are always double, so that they sum to 1 closely for any N.
template <class Real, class Ray>
void for_each_cosine_ray(int rays, std::uint32_t seed, int x, int y, const glm::vec<3, Real>& n,
                         Ray&& ray) {
  using Vec3 = glm::vec<3, Real>;
  Vec3 t, b;
  tangent_frame(n, t, b);
  const int columns = std::max(1, int(std::sqrt(double(rays))));
  const std::uint32_t pixel = pixel_hash(seed, x, y);
  std::uint32_t k = 0;
  for (int c = 0; c < columns; ++c) {
    const int rows = int(std::int64_t(c + 1) * rays / columns - std::int64_t(c) * rays / columns);
    const double weight = 1.0 / (double(columns) * rows);
    for (int r = 0; r < rows; ++r, ++k) {
      Real u1, u2;
      if constexpr (std::is_same_v<Real, float>) {
        u1 = (Real(c) + pixel_stream_random(pixel, 2 * k)) * (1.0f / float(columns));
        u2 = (Real(r) + pixel_stream_random(pixel, 2 * k + 1)) * (1.0f / float(rows));
      } else {
        u1 = (Real(c) + Real(pixel_stream_random(pixel, 2 * k))) / Real(columns);
        u2 = (Real(r) + Real(pixel_stream_random(pixel, 2 * k + 1))) / Real(rows);
      }
      // Malley's method: a uniform point of the disk lifted to the hemisphere is
      // cosine-distributed about n.
      const glm::vec<2, Real> q = concentric_disk(u1, u2);
      const Real up = std::sqrt(std::max(Real(0), Real(1) - q.x * q.x - q.y * q.y));
      ray(glm::normalize(q.x * t + q.y * b + up * n), weight);
    }
  }
}

/// The strata of for_each_cosine_ray for one ray count, as tables per ray, so that a SIMD
/// kernel can draw the rays of a pixel in vectors: ray k lies in column columns_k, row rows_k
/// of a column of `rows_per_column_k` rows, with weight weight_k. Padded with copies of ray 0
/// to a multiple of 16 (the widest vector), so that whole vectors can be loaded.
struct CosineStrata {
  explicit CosineStrata(int rays);
  int rays;
  int columns;
  std::vector<float> column, row, inv_rows;  ///< per ray, as floats
  std::vector<double> weight;                ///< per ray, the area of its stratum
};

/// The directions of for_each_cosine_ray<float>(strata.rays, ...) at the pixel whose
/// pixel_hash is `pixel`, about the unit normal n, as arrays dx, dy, dz of strata.rays floats
/// (room for the padding: strata.column.size()), in SIMD (Highway, the best target of this
/// CPU). They differ from the scalar ones by float rounding (the sines and cosines are
/// Highway's, the divisions reciprocals): at most a few units of 1e-7 per component
/// (cosine_hemisphere_test.cpp).
void cosine_directions(const CosineStrata& strata, std::uint32_t pixel, const glm::vec3& n,
                       float* dx, float* dy, float* dz);

}  // namespace aolab
