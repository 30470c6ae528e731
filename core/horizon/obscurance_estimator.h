// The obscurance estimator of Alchemy AO (McGuire, Osman, Bukowski, Hennessy, "The Alchemy
// Screen-Space Ambient Obscurance Algorithm", HPG 2011) and of Scalable AO (McGuire, Mara,
// Luebke, "Scalable Ambient Obscurance", HPG 2012, which keeps Alchemy's estimator), and the
// spiral of taps both place on the projected disc. One implementation serves `alchemy` and
// `sao`; docs/methods/alchemy.md derives it.
//
//   A = max(0, 1 − (c·σ·r/s) Σ_{i=1..s} w(v_i) · max(0, v_i·n̂ − b) / (v_i·v_i + ε·r²))^k
//
// v_i = P_i − C (view space), n̂ C's normal, b the bias distance (Alchemy: −z_C·β, i.e. β
// times C's depth; SAO's reference code: a constant distance), w and c from the falloff:
// Alchemy's hard cut at r (w = [v·v < r²], c = 2, Alchemy's estimator) or the smooth
// (1 − v·v/r²)³ of SAO's reference implementation (c = 5). σ and ε are measured in units of
// r and r² (the papers give them in scene units): a scene scaled together with its radius
// then gives the same AO (docs/conventions.md), and at r = 1 the numbers are the papers'.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <numbers>
#include <vector>

#include "core/base/camera.h"
#include "core/horizon/receiver.h"
#include "core/sampling/random.h"

namespace aolab {

/// τ, the turns of the spiral of s taps (s = 1..98), chosen to minimise the discrepancy of
/// the taps: the SAO paper's table (§2.3), as its reference implementation lists it.
inline constexpr int kSpiralTurns[] = {
    1,  1,  2,  3,  2,  5,  2,  3,  2,  3,  3,  5,  5,  3,  4,  7,  5,  5,  7,  9,
    8,  5,  5,  7,  7,  7,  8,  5,  8,  11, 12, 7,  10, 13, 8,  11, 8,  7,  14, 11,
    11, 13, 12, 13, 19, 17, 13, 11, 18, 19, 11, 11, 14, 17, 21, 15, 16, 17, 18, 13,
    17, 11, 17, 19, 18, 25, 18, 19, 19, 29, 21, 19, 27, 31, 29, 21, 18, 17, 29, 31,
    31, 23, 18, 25, 26, 25, 23, 19, 34, 19, 27, 21, 25, 39, 29, 17, 21, 27};

/// The largest tap count the table covers, and so the largest `samples` setting.
constexpr int kSpiralMaxSamples = int(std::size(kSpiralTurns));

/// The turns for s taps: `turns` if > 0, else the table's τ(s).
inline int spiral_turns(int samples, int turns) {
  return turns > 0 ? turns : kSpiralTurns[std::clamp(samples, 1, kSpiralMaxSamples) - 1];
}

/// The falloff w(v) of the estimator and its constant c.
enum class ObscuranceFalloff : int {
  /// Alchemy's estimator (HPG 2011): taps beyond r dropped (w = [v·v < r²]), c = 2.
  Alchemy = 0,
  /// SAO's reference implementation's smoother falloff, "recommended" there:
  /// w = (1 − v·v/r²)³ (its (r² − v·v)³/r⁶), c = 5.
  Smooth = 1,
};

/// The spiral of SAO §2.3 (Alchemy's reference implementation places its taps the same way):
/// tap i at α_i = (i + ½)/s of the projected radius, angle θ_i = 2π·α_i·τ + φ, φ the pixel's
/// rotation. Holds α_i and cos/sin of 2π·α_i·τ; a pixel rotates them by φ with one sincos
/// (angle addition), so there is no trigonometry per tap.
class SpiralTaps {
 public:
  SpiralTaps(int samples, int turns) {
    const int tau = spiral_turns(samples, turns);
    for (int i = 0; i < samples; ++i) {
      const double alpha = (i + 0.5) / samples;
      const double theta = 2.0 * std::numbers::pi * alpha * tau;
      alpha_.push_back(float(alpha));
      cos_.push_back(float(std::cos(theta)));
      sin_.push_back(float(std::sin(theta)));
    }
  }
  int size() const { return int(alpha_.size()); }
  float alpha(int i) const { return alpha_[std::size_t(i)]; }
  /// cos and sin of θ_i for the rotation whose cos and sin are (cr, sr).
  void direction(int i, float cr, float sr, float& c, float& s) const {
    c = cos_[std::size_t(i)] * cr - sin_[std::size_t(i)] * sr;
    s = sin_[std::size_t(i)] * cr + cos_[std::size_t(i)] * sr;
  }

 private:
  std::vector<float> alpha_, cos_, sin_;
};

/// The estimator with its settings folded in, in double: r² reaches 1e60 at R = 1e30.
struct ObscuranceEstimator {
  double r2 = 1.0;       ///< r²
  double inv_r2 = 1.0;   ///< 1/r²
  double epsilon = 0.0;  ///< ε·r², the paper's ε in scene units²
  double scale = 0.0;    ///< c·σ·r/s
  double contrast = 1.0;
  ObscuranceFalloff falloff = ObscuranceFalloff::Alchemy;

  /// r: radius; intensity: σ (units of r); epsilon: ε (units of r²); contrast: k.
  ObscuranceEstimator(float radius, int samples, float intensity, float epsilon_r2, float k,
                      int falloff_choice)
      : r2(double(radius) * radius),
        inv_r2(1.0 / r2),
        epsilon(double(epsilon_r2) * r2),
        contrast(k),
        falloff(ObscuranceFalloff(falloff_choice)) {
    const double c = falloff == ObscuranceFalloff::Smooth ? 5.0 : 2.0;
    scale = c * double(intensity) * double(radius) / samples;
  }

  /// One tap's term w(v)·max(0, v·n − b)/(v·v + ε): vv = v·v, vn = v·n, bias = b.
  double term(double vv, double vn, double bias) const {
    if (!(vv < r2)) return 0.0;  // beyond r (and NaN): w = 0 for both falloffs
    const double num = vn - bias;
    if (!(num > 0.0)) return 0.0;
    double t = num / (vv + epsilon);
    if (falloff == ObscuranceFalloff::Smooth) {
      const double f = 1.0 - vv * inv_r2;
      t *= f * f * f;
    }
    return t;
  }

  /// max(0, 1 − scale·Σ)^k in [0, 1]; exactly 1 when no tap contributed.
  float visibility(double sum) const {
    if (!(sum > 0.0)) return 1.0f;
    double a = std::max(0.0, 1.0 - scale * sum);
    if (contrast != 1.0) a = std::pow(a, contrast);
    return float(std::clamp(a, 0.0, 1.0));
  }
};

/// The term of one tap for the receiver p: the surface point on pixel (sx, sy) at depth ds
/// (its texel centre), v = S − C formed without cancellation (HBAO's form). The cheap tests
/// (beyond r, v·n ≤ b) come first; of the rest, taps not above
/// C's tangent plane by more than float32 rounding add nothing (above_tangent_plane):
/// their v·n ≤ 0 in exact arithmetic, so this only removes rounding noise, and an open plane
/// gives exactly 1.
inline double obscurance_tap(const HorizonReceiver& p, int sx, int sy, float ds, double bias,
                             const ObscuranceEstimator& e) {
  const float qx = float(sx - p.x), qy = float(sy - p.y);
  const float dd = ds - p.d;
  const glm::vec3 v((qx * ds + p.ox * dd) * p.inv_fx, -(qy * ds + p.oy * dd) * p.inv_fy, -dd);
  const double vv = double(v.x) * v.x + double(v.y) * v.y + double(v.z) * v.z;
  if (!(vv < e.r2)) return 0.0;  // beyond r: w = 0 for both falloffs
  const double vn = double(v.x) * p.n.x + double(v.y) * p.n.y + double(v.z) * p.n.z;
  if (!(vn > bias)) return 0.0;  // the term's max(0, ·) is 0: no need for the dearer test
  if (!above_tangent_plane(p, qx, qy, ds)) return 0.0;
  return e.term(vv, vn, bias);
}

/// The estimate at pixel (x, y), depth d, normal n (Alchemy §3, SAO §2.3): the spiral rotated
/// by the pixel's angle (`pixel_random` stream 0, or 0 without `random_rotation`) and scaled to
/// the disc of radius r at depth d, r·fx/d pixels across and r·fy/d down (a disc in view
/// space for any pixel aspect); each tap inside the image is handed, with the texel (sx, sy)
/// it falls in, to read(i, sx, sy, ds), which sets the depth ds and may move (sx, sy) to the
/// pixel of the surface point the tap stands for, and returns false for background; taps off the
/// image (the test also rejects inf/NaN at huge radii) or on C's own pixel (v = 0) add nothing.
template <class ReadTap>
float obscurance_estimate(const CameraIntrinsics& cam, int x, int y, float d, const glm::vec3& n,
                          float radius, bool random_rotation, int seed, double bias,
                          const SpiralTaps& taps, const ObscuranceEstimator& e, int width,
                          int height, ReadTap&& read) {
  const HorizonReceiver p = horizon_receiver(cam, x, y, d, n);
  const float rx = radius * cam.fx / d, ry = radius * cam.fy / d;
  const float phi = random_rotation ? 2.0f * std::numbers::pi_v<float> *
                                          pixel_random(std::uint32_t(seed), x, y, 0)
                                    : 0.0f;
  const float cr = std::cos(phi), sr = std::sin(phi);
  double sum = 0.0;
  for (int i = 0; i < taps.size(); ++i) {
    float c, sn;
    taps.direction(i, cr, sr, c, sn);
    const float a = taps.alpha(i);
    const float sx_f = p.px + a * c * rx, sy_f = p.py - a * sn * ry;  // image y points down
    if (!(sx_f >= 0.0f && sx_f < float(width) && sy_f >= 0.0f && sy_f < float(height))) continue;
    int sx = int(sx_f), sy = int(sy_f);  // the texel the tap falls in
    float ds;
    if (!read(i, sx, sy, ds)) continue;  // background never occludes
    if (sx == x && sy == y) continue;
    sum += obscurance_tap(p, sx, sy, ds, bias, e);
  }
  return e.visibility(sum);
}

}  // namespace aolab
