// The receiver P of the horizon-based methods (HBAO, Pyramid HBAO, GTAO, the visibility bitmask,
// Alchemy AO, SAO) and the per-sample tangent-plane test they share, which keeps an open plane
// exactly unoccluded whatever float32 rounding and texel snapping do to its samples
// (docs/methods/hbao.md gives the derivation).
#pragma once

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <limits>

#include "core/base/camera.h"

namespace aolab {

/// Float32 rounding must not create occlusion: with per-sample tangents a sample counts only
/// if it lies nearer than the tangent plane, along its own view ray, by more than
/// 2^-24 · depth · (kTangentDepthUlps + kTangentNormalUlps · g), g = |r|/|n·r| summed over P's
/// and the sample's rays (how much normal rounding moves a tangent-plane depth; large at
/// grazing angles). HBAO's per-direction tangent uses kTangentDepthUlps too (hbao.h). Either
/// way an unoccluded plane gives exactly 1; only occluders within a few ulps of depth of the
/// tangent plane are lost.
constexpr float kTangentDepthUlps = 8.0f;
constexpr float kTangentNormalUlps = 4.0f;

/// What the tangent-plane tests need of the receiver P at pixel (x, y), computed once per
/// pixel.
struct HorizonReceiver {
  int x, y;
  float d;       ///< P's depth
  glm::vec3 n;   ///< P's prepared normal
  float px, py;  ///< P's pixel centre
  float ox, oy;  ///< offsets of P's pixel centre from (cx, cy)
  float inv_fx, inv_fy;
  float n_r0;       ///< n · (P's view ray at depth 1)
  float grazing_p;  ///< |r0| / |n·r0|: how much normal rounding moves tangent-plane depths here
};

HorizonReceiver horizon_receiver(const CameraIntrinsics& cam, int x, int y, float depth,
                                 const glm::vec3& normal);

/// Whether a sample on P's pixel + (qx, qy), at depth ds, lies nearer than P's tangent plane
/// along its own view ray by more than float32 rounding: the plane meets that ray at depth
/// tau = d (n·r0)/(n·rs), and the sample counts only if tau − ds exceeds
/// 2^-24 · max(ds, tau) · (kTangentDepthUlps + kTangentNormalUlps · g), g summing |r|/|n·r| of
/// both rays. A ray that never meets the plane in front of the camera counts any finite sample.
/// (v·n = (n·rs)(ds − tau) for v = S − P, so this is "v·n > 0" made immune to rounding.)
/// HBAO's per-sample tangent test, shared with GTAO, Alchemy AO and SAO: an open plane never
/// occludes itself, whatever snapping does to the samples. Inline: it runs once per sample.
inline bool above_tangent_plane(const HorizonReceiver& p, float qx, float qy, float ds) {
  constexpr float kUnitRoundoff = 1.0f / 16777216.0f;  // 2^-24, unit roundoff of float32
  const glm::vec3 rs((p.ox + qx) * p.inv_fx, -(p.oy + qy) * p.inv_fy, -1.0f);
  const float n_rs = glm::dot(p.n, rs);
  const float tau = p.d * p.n_r0 / n_rs;  // depth where rs meets the tangent plane
  const bool hits = n_rs < 0.0f && tau > 0.0f && std::isfinite(tau);
  if (hits && !(tau > ds)) return false;
  const float grazing_s = glm::length(rs) / std::abs(n_rs);
  const float tolerance = kUnitRoundoff * std::max(ds, hits ? tau : ds) *
                          (kTangentDepthUlps + kTangentNormalUlps * (p.grazing_p + grazing_s));
  return (hits ? tau : std::numeric_limits<float>::infinity()) - ds > tolerance;
}

}  // namespace aolab
