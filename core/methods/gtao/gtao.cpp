#include "core/methods/gtao/gtao.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <numbers>
#include <vector>

#include "core/base/parallel.h"
#include "core/horizon/slice.h"
#include "core/methods/gtao/gtao_shared.h"

namespace aolab {

float gtao_multi_bounce(float ao, float albedo) {
  // The memo's multi-bounce fit (its multiple-bounce section): a cubic in AO whose
  // coefficients are linear in the albedo.
  const float a = kGtaoBounceA[0] * albedo + kGtaoBounceA[1];
  const float b = kGtaoBounceB[0] * albedo + kGtaoBounceB[1];
  const float c = kGtaoBounceC[0] * albedo + kGtaoBounceC[1];
  return std::max(ao, ((a * ao + b) * ao + c) * ao);
}

double gtao_arc(double h, double n, double cos_n, double sin_n) {
  return 0.25 * (-std::cos(2.0 * h - n) + cos_n + 2.0 * h * sin_n);  // eq. 7
}

double gtao_arc(double h, double n) { return gtao_arc(h, n, std::cos(n), std::sin(n)); }

namespace {

constexpr double kHalfPi = std::numbers::pi / 2.0;

// A GTAO slice: the shared geometry (core/horizon/slice.h) and eq. 7 of each side with its horizon
// at the tangent.
struct Slice : SliceGeometry {
  double open_arc[2];
};

// Eq. 7 of one side from its horizon cosine: h2 = acos c on side 0, h1 = −acos c on side 1,
// clamped to the hemisphere around proj n, h1 = n + max(h1 − n, −π/2), h2 = n + min(h2 − n, π/2).
double side_arc(const SliceGeometry& sl, float horizon_cos, int side) {
  const double h = std::acos(std::clamp(double(horizon_cos), -1.0, 1.0));
  const double clamped =
      side == 0 ? sl.n + std::min(h - sl.n, kHalfPi) : sl.n + std::max(-h - sl.n, -kHalfPi);
  return gtao_arc(clamped, sl.n, sl.cos_n, sl.sin_n);
}

Slice make_slice(const SliceFrame& f, const GtaoSettings& s, const HorizonReceiver& p,
                 const glm::vec3& v, float c, float sn) {
  Slice sl{make_slice_geometry(f.cam, s.radius, s.steps, p, v, c, sn), {}};
  sl.open_arc[0] = side_arc(sl, sl.low[0], 0);
  sl.open_arc[1] = side_arc(sl, sl.low[1], 1);
  return sl;
}

// The horizon cosine one sample offers on a side whose tangent cosine is `low`: the cosine
// from v of D = S − P projected onto the slice plane, faded towards `low` by the falloff
// weight, and `low` itself for samples beyond R or not above the tangent plane.
float sample_horizon_cos(const HorizonReceiver& p, const GtaoSettings& s, const Slice& sl,
                         const glm::vec3& v, float low, float horizon, int sx, int sy, float ds) {
  const float qx = float(sx - p.x), qy = float(sy - p.y);
  const glm::vec3 D = slice_sample_offset(p, qx, qy, ds);
  const float r2 = glm::dot(D, D);
  const float radius = s.radius;
  float weight = 1.0f;
  if (s.falloff > 0.0f) {
    // XeGTAO's fade over the last `falloff`·R of the radius (its take on the memo's §4.3,
    // "Bounding the sampling area").
    weight = std::clamp((radius - std::sqrt(r2)) / (s.falloff * radius), 0.0f, 1.0f);
  } else if (!(r2 <= radius * radius)) {
    weight = 0.0f;  // the memo's hard cut at R
  }
  if (!(weight > 0.0f)) return low;
  const float along_axis = glm::dot(D, sl.axis);
  const float in_plane2 = r2 - along_axis * along_axis;  // |D projected onto the slice|²
  if (!(in_plane2 > 0.0f)) return low;
  const float cos_h = glm::dot(D, v) / std::sqrt(in_plane2);  // axis ⊥ v: D_p·v = D·v
  const float faded = std::max(low, weight >= 1.0f ? cos_h : low + weight * (cos_h - low));
  // Without the thickness heuristic a sample at or below the horizon changes nothing whether
  // it counts or not, so the dearer tangent test is left out for it.
  if (s.thickness == 0.0f && faded <= horizon) return low;
  return above_tangent_plane(p, qx, qy, ds) ? faded : low;
}

// The horizon cosine of one side (sign +1: side 0, −1: side 1): the max over its samples
// (Algorithm 1's horizon search), or with the thickness heuristic a sample below the current
// horizon pulls it towards itself by `thickness` (§4.3, "Height-field assumption
// considerations").
float search_horizon(const SliceFrame& f, const GtaoSettings& s, const HorizonReceiver& p,
                     const Slice& sl, const glm::vec3& v, float jitter, int side) {
  const float low = sl.low[side];
  float horizon = low;
  march_slice_side(f, p, sl, s.steps, jitter, side, [&](int sx, int sy, float ds) {
    const float shc = sample_horizon_cos(p, s, sl, v, low, horizon, sx, sy, ds);
    if (shc > horizon) {
      horizon = shc;
    } else if (s.thickness > 0.0f) {
      horizon = std::max(low, horizon + s.thickness * (shc - horizon));
    }
    return true;
  });
  return horizon;
}

// |proj n| · (a(h1) + a(h2)) of a slice (eq. 7 per side, eq. 8 weight); a side whose horizon
// stayed at the tangent reuses the open slice's arc, so an open slice gives the same bits.
double slice_visibility(const Slice& sl, const float horizon_cos[2]) {
  double sum = 0.0;
  for (int side = 0; side < 2; ++side)
    sum += horizon_cos[side] == sl.low[side] ? sl.open_arc[side]
                                             : side_arc(sl, horizon_cos[side], side);
  return double(sl.length) * sum;
}

float gtao_pixel(const SliceFrame& f, const GtaoSettings& s, const HorizonDirections& directions,
                 int x, int y, float* dir_cos, float* dir_sin) {
  SlicePixel px;
  if (!slice_pixel(f, directions, x, y, s.seed, s.random_rotation, s.jitter, dir_cos, dir_sin, px))
    return 1.0f;  // background
  const HorizonReceiver& p = px.p;
  const glm::vec3& v = px.v;
  const float jitter = px.jitter;
  double visible = 0.0, open = 0.0;
  for (int k = 0; k < s.slices; ++k) {
    const Slice sl = make_slice(f, s, p, v, dir_cos[k], dir_sin[k]);
    if (!(sl.length > 0.0f)) continue;  // proj n = 0: the slice carries no weight (eq. 8)
    const float horizon_cos[2] = {search_horizon(f, s, p, sl, v, jitter, 0),
                                  search_horizon(f, s, p, sl, v, jitter, 1)};
    visible += slice_visibility(sl, horizon_cos);
    // The same slice with nothing above the tangent plane: bit for bit `visible`'s term when
    // no sample raised a horizon.
    open += slice_visibility(sl, sl.low);
  }
  double ao = 1.0;
  if (s.normalization == int(GtaoNormalization::Slices))
    ao = visible / double(s.slices);  // (1/π) ∫_0^π dφ by the mean over the slices
  else if (open > 0.0)
    ao = visible / open;
  float out = std::clamp(float(ao), 0.0f, 1.0f);
  if (s.multi_bounce) out = std::clamp(gtao_multi_bounce(out, s.albedo), 0.0f, 1.0f);
  return out;
}

}  // namespace

Image gtao(const GBuffer& g, const GtaoSettings& s, const RunOptions& options) {
  g.validate();
  require_normal(g, "gtao");
  validate_settings(s, kGtaoFields);
  return run_slice_method(
      g, s.slices, 0.0f, options,
      [&](const SliceFrame& f, const HorizonDirections& directions, int x, int y, float* dir_cos,
          float* dir_sin) { return gtao_pixel(f, s, directions, x, y, dir_cos, dir_sin); },
      [&](const SliceFrame& f, int threads, Progress* progress) {
        return gtao_simd(f, s, threads, progress);
      });
}

Method gtao_method() {
  Method m = registered_method(
      "gtao", "Ground-truth-based ambient occlusion",
      "Jimenez, Wu, Pesce, Jarabo 2016, Practical Real-Time Strategies for Accurate Indirect "
      "Occlusion",
      kGtaoFields, gtao);
  m.needs_normal = true;
  m.has_simd_kernel = true;
  return m;
}

}  // namespace aolab
