// GTAO's SIMD kernel: the scalar per-pixel code of gtao.cpp (the oracle it is tested against)
// on Lanes consecutive pixels of a row at once, compiled by Highway for every target and
// dispatched at run time. Every setting is supported. The slice set-up, the march and the
// tangent test are shared with the visibility bitmask (core/horizon/slice_simd-inl.h).
//
// What it does differently (docs/methods/gtao.md, "SIMD kernel"):
// - float instead of double for eq. 7, with cos(2h − n) from cos h = c and sin h = ±√(1 − c²)
//   by the double-angle formulas: the only transcendental per side is acos c, and per slice
//   atan2 for n (the linear term of eq. 7 needs the angles themselves);
// - the open slice's sides are eq. 7's closed form at n ± π/2, ¼(2 cos n + (2n ± π) sin n),
//   and a side whose horizon stayed at its tangent takes that value, so an open plane still
//   gives the same bits for the visible and the unoccluded sums, hence exactly 1;
// - the slice set-up of core/horizon/slice_simd-inl.h (no sin/cos of n, one reciprocal square root
//   per normalisation, HBAO's division-free prefilter before the tangent test).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/methods/gtao/gtao_simd.cpp"

#include <algorithm>
#include <cstddef>
#include <numbers>

#include "core/base/parallel.h"
#include "core/base/simd-inl.h"
#include "core/base/simd_tiles.h"
#include "core/horizon/slice.h"
#include "core/horizon/slice_simd-inl.h"
#include "core/methods/gtao/gtao.h"
#include "core/methods/gtao/gtao_shared.h"

HWY_BEFORE_NAMESPACE();
namespace aolab::HWY_NAMESPACE {
namespace {
using namespace slice_simd;

// Eq. 7 of one side from its horizon cosine c (side_arc): h = acos c on side 0, −acos c on
// side 1, clamped to the hemisphere around proj n; ¼(−cos(2h − n) + cos n + 2h sin n) with
// cos(2h − n) = cos 2h cos n + sin 2h sin n, cos 2h = 2c² − 1, sin 2h = 2c·sin h. The clamp
// binds only by rounding (a horizon never falls below its tangent), so it is applied to the
// linear term alone.
HWY_INLINE VF SideArc(DF df, const Slice& sl, VF c, int side) {
  const VF one = hn::Set(df, 1.0f);
  c = hn::Min(hn::Max(c, hn::Neg(one)), one);
  const VF acos_c = hn::Acos(df, c);
  const VF half_pi = hn::Set(df, float(std::numbers::pi / 2));
  const VF h = side == 0 ? hn::Min(acos_c, hn::Add(sl.n, half_pi))
                         : hn::Max(hn::Neg(acos_c), hn::Sub(sl.n, half_pi));
  const VF sin_h_abs = hn::Sqrt(hn::Max(hn::Zero(df), hn::NegMulAdd(c, c, one)));
  const VF cos_2h = hn::MulAdd(hn::Add(c, c), c, hn::Neg(one));
  const VF sin_2h_abs = hn::Mul(hn::Add(c, c), sin_h_abs);
  const VF sin_2h = side == 0 ? sin_2h_abs : hn::Neg(sin_2h_abs);
  const VF cos_2h_n = hn::MulAdd(cos_2h, sl.cos_n, hn::Mul(sin_2h, sl.sin_n));
  const VF sum = hn::Add(hn::Sub(sl.cos_n, cos_2h_n), hn::Mul(hn::Add(h, h), sl.sin_n));
  return hn::Mul(hn::Set(df, 0.25f), sum);
}

// The horizon search of both sides (search_horizon with sample_horizon_cos) on every lane:
// horizon[side] starts at the side's tangent cosine.
HWY_INLINE void SearchHorizons(DF df, const SliceFrame& f, const GtaoSettings& s, const Row& k,
                               const Pixels& p, const Slice& sl, VF horizon[2]) {
  const VF zero = hn::Zero(df), one = hn::Set(df, 1.0f);
  const VF radius = hn::Set(df, s.radius), radius2 = hn::Set(df, s.radius * s.radius);
  const VF inv_fade = hn::Set(df, s.falloff > 0.0f ? 1.0f / (s.falloff * s.radius) : 0.0f);
  const VF thickness = hn::Set(df, s.thickness);
  horizon[0] = sl.low[0], horizon[1] = sl.low[1];
  march_sides(df, f, k, p, sl, s.steps, [&](int side, MF visited, VI sx, VI sy, VF ds) {
    const VF low = sl.low[side];
    const Offset o = sample_offset(df, k, p, sx, sy, ds);
    VF weight;
    if (s.falloff > 0.0f) {
      // XeGTAO's fade over the last `falloff`·R of the radius.
      const VF r = hn::Sqrt(o.r2);
      weight = hn::Min(hn::Max(hn::Mul(hn::Sub(radius, r), inv_fade), zero), one);
    } else {
      weight = hn::IfThenElseZero(hn::Le(o.r2, radius2), one);  // the memo's hard cut at R
    }
    const VF along_axis = hn::MulAdd(o.x, sl.ax, hn::MulAdd(o.y, sl.ay, hn::Mul(o.z, sl.az)));
    const VF in_plane2 = hn::NegMulAdd(along_axis, along_axis, o.r2);
    const MF ok = hn::And(visited, hn::And(hn::Gt(weight, zero), hn::Gt(in_plane2, zero)));
    VF faded = low;
    if (!hn::AllFalse(df, ok)) {
      const VF along_v = hn::MulAdd(o.x, p.vx, hn::MulAdd(o.y, p.vy, hn::Mul(o.z, p.vz)));
      const VF cos_h = hn::Mul(along_v, RecipSqrt(df, hn::IfThenElse(ok, in_plane2, one)));
      const VF blended =
          hn::IfThenElse(hn::Ge(weight, one), cos_h, hn::MulAdd(weight, hn::Sub(cos_h, low), low));
      faded = hn::IfThenElse(ok, hn::Max(low, blended), low);
    }
    VF& h = horizon[side];
    if (s.thickness == 0.0f) {
      // A sample at or below the horizon changes nothing: the tangent test only for the others.
      const MF raises = hn::And(ok, hn::Gt(faded, h));
      if (hn::AllFalse(df, raises)) return;
      const MF counts = above_tangent_plane(df, k, p, raises, o.qx, o.qy, ds);
      h = hn::IfThenElse(counts, faded, h);
    } else {
      // §4.3's thickness heuristic: a sample below the horizon pulls it towards itself.
      const MF counts = above_tangent_plane(df, k, p, ok, o.qx, o.qy, ds);
      const VF shc = hn::IfThenElse(counts, faded, low);
      const VF pulled = hn::Max(low, hn::MulAdd(thickness, hn::Sub(shc, h), h));
      const VF next = hn::IfThenElse(hn::Gt(shc, h), shc, pulled);
      h = hn::IfThenElse(visited, next, h);
    }
  });
}

}  // namespace

// Pixels [x_begin, x_end) of row y of GTAO into out (the row): gtao_pixel on Lanes pixels at
// a time. base_cos/sin: the unrotated table of 2·slices directions (HorizonDirections).
void GtaoSpan(const SliceFrame& f, const GtaoSettings& s, const float* base_cos,
              const float* base_sin, int y, int x_begin, int x_end, float* HWY_RESTRICT out) {
  const DF df;
  const Row k = make_row(df, f, y);
  const VF zero = hn::Zero(df), one = hn::Set(df, 1.0f);
  const VF pi_quarter = hn::Set(df, float(std::numbers::pi / 4));
  ForEachSpanVector(df, x_begin, x_end, [&](int x0, int count) {
    const Pixels p = load_pixels(df, f, k, x0, count, s.seed, s.random_rotation, s.jitter,
                                 2 * s.slices, s.radius, s.steps);
    VF result = one;
    if (!hn::AllFalse(df, p.geometry)) {
      VF visible = zero, open = zero;
      for (int slice = 0; slice < s.slices; ++slice) {
        const Slice sl = make_slice(df, k, p, base_cos[slice], base_sin[slice]);
        if (hn::AllFalse(df, sl.active)) continue;
        VF horizon[2];
        SearchHorizons(df, f, s, k, p, sl, horizon);
        const VF horizon0 = horizon[0], horizon1 = horizon[1];
        // The open sides, eq. 7 at h = n ± π/2: ¼(2 cos n + 2n sin n) ± (π/4) sin n.
        const VF base = hn::Mul(hn::Set(df, 0.5f), hn::MulAdd(sl.n, sl.sin_n, sl.cos_n));
        const VF open0 = hn::MulAdd(pi_quarter, sl.sin_n, base);
        const VF open1 = hn::NegMulAdd(pi_quarter, sl.sin_n, base);
        const MF raised0 = hn::Ne(horizon0, sl.low[0]), raised1 = hn::Ne(horizon1, sl.low[1]);
        VF side0 = open0, side1 = open1;
        if (!hn::AllFalse(df, raised0))
          side0 = hn::IfThenElse(raised0, SideArc(df, sl, horizon0, 0), open0);
        if (!hn::AllFalse(df, raised1))
          side1 = hn::IfThenElse(raised1, SideArc(df, sl, horizon1, 1), open1);
        // Inactive lanes have length 0 and add nothing. Both sums take the same operations,
        // so where no horizon rose they are the same bits.
        visible = hn::MulAdd(sl.length, hn::Add(side0, side1), visible);
        open = hn::MulAdd(sl.length, hn::Add(open0, open1), open);
      }
      VF ao;
      if (s.normalization == int(GtaoNormalization::Slices)) {
        ao = hn::Div(visible, hn::Set(df, float(s.slices)));
      } else {
        const MF has_open = hn::Gt(open, zero);
        ao = hn::IfThenElse(has_open, hn::Div(visible, hn::IfThenElse(has_open, open, one)), one);
      }
      ao = hn::Min(hn::Max(ao, zero), one);
      if (s.multi_bounce) {
        // The fit per lane by the scalar function itself: a few flops per pixel, and the same
        // bits for the same AO (a vector form would fuse its multiplies and adds).
        HWY_ALIGN float lanes[hn::MaxLanes(df)];
        hn::Store(ao, df, lanes);
        for (std::size_t i = 0; i < hn::Lanes(df); ++i)
          lanes[i] = std::clamp(gtao_multi_bounce(lanes[i], s.albedo), 0.0f, 1.0f);
        ao = hn::Load(df, lanes);
      }
      result = hn::IfThenElse(p.geometry, ao, one);
    }
    StoreRowPart(df, result, count, out + x0);
  });
}

}  // namespace aolab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace aolab {

HWY_EXPORT(GtaoSpan);

Image gtao_simd(const SliceFrame& f, const GtaoSettings& s, int threads, Progress* progress) {
  const HorizonDirections directions(2 * s.slices);
  return image_from_simd_tiles(
      f.width, f.height, threads, progress, [&](int y, int x0, int x1, float* out) {
        HWY_DYNAMIC_DISPATCH(GtaoSpan)
        (f, s, directions.base_cos(), directions.base_sin(), y, x0, x1, out);
      });
}

}  // namespace aolab
#endif  // HWY_ONCE
