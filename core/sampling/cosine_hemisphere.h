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

#include "core/sampling/random.h"

namespace aolab {

/// Shirley & Chiu's concentric map of [0, 1)² onto the unit disk: equal areas to equal areas
/// with little distortion, so the square's strata stay compact on the disk.
inline glm::dvec2 concentric_disk(double u1, double u2) {
  const double a = 2.0 * u1 - 1.0, b = 2.0 * u2 - 1.0;
  if (a == 0.0 && b == 0.0) return {0.0, 0.0};
  constexpr double quarter = std::numbers::pi / 4.0;
  double r, phi;
  if (std::abs(a) > std::abs(b))
    r = a, phi = quarter * (b / a);
  else
    r = b, phi = 2.0 * quarter - quarter * (a / b);
  return {r * std::cos(phi), r * std::sin(phi)};
}

/// A tangent frame (t, b) for the unit normal n: Duff et al., "Building an Orthonormal Basis,
/// Revisited" (JCGT 2017), listing 3; no branch on a threshold, so no seam.
inline void tangent_frame(const glm::dvec3& n, glm::dvec3& t, glm::dvec3& b) {
  const double sign = std::copysign(1.0, n.z);
  const double a = -1.0 / (sign + n.z);
  const double c = n.x * n.y * a;
  t = {1.0 + sign * n.x * n.x * a, sign * c, -sign * n.x};
  b = {c, sign + n.y * n.y * a, -n.y};
}

/// Calls ray(ω, w) for the `rays` stratified cosine-weighted directions ω about the unit
/// normal n of pixel (x, y), w being the area of ω's stratum. ⌊√N⌋ columns of the unit square;
/// column c holds n_c rows, so that the N strata tile the square for any N; the weights sum to
/// 1, so summing only the blocked ones keeps an unoccluded pixel exactly 1. Ray k is jittered
/// in its stratum by pixel_random(seed, x, y, 2k) and (.., 2k + 1): the same directions for
/// the same pixel whatever the thread.
template <class Ray>
void for_each_cosine_ray(int rays, std::uint32_t seed, int x, int y, const glm::dvec3& n,
                         Ray&& ray) {
  glm::dvec3 t, b;
  tangent_frame(n, t, b);
  const int columns = std::max(1, int(std::sqrt(double(rays))));
  std::uint32_t k = 0;
  for (int c = 0; c < columns; ++c) {
    const int rows = int(std::int64_t(c + 1) * rays / columns - std::int64_t(c) * rays / columns);
    const double weight = 1.0 / (double(columns) * rows);
    for (int r = 0; r < rows; ++r, ++k) {
      const double u1 = (c + double(pixel_random(seed, x, y, 2 * k))) / columns;
      const double u2 = (r + double(pixel_random(seed, x, y, 2 * k + 1))) / rows;
      // Malley's method: a uniform point of the disk lifted to the hemisphere is
      // cosine-distributed about n.
      const glm::dvec2 q = concentric_disk(u1, u2);
      const double up = std::sqrt(std::max(0.0, 1.0 - q.x * q.x - q.y * q.y));
      ray(glm::normalize(q.x * t + q.y * b + up * n), weight);
    }
  }
}

}  // namespace aolab
