// Pyramid HBAO's SIMD kernel: the scalar per-pixel code of pyramid_hbao.cpp (the oracle it is
// tested against) on Lanes consecutive pixels of a row at once, compiled by Highway for every
// target and dispatched at run time. Every setting is supported; each lane follows the scalar
// pixel's steps (its own directions and start steps, the same reads on the same levels, the
// same tests), so the two differ only by float rounding (FMA, the sine and cosine).
//
// What it does differently (docs/methods/pyramid_hbao.md, "SIMD kernel"):
// - the levels are laid out for gathers (GatherPyramid): one array of depths per level, with a
//   border of background texels; a texel's depth has its sign bit set where its centroid is
//   not its footprint's centre (the image border or background cut the footprint). A read
//   then gathers one float and computes the centroid from the texel's coordinates; the
//   centroid gathers run only in the exact test, for marked texels;
// - a read's texel is ⌊x / K^l⌋ from its position in texels of its level (the scalar code's
//   ⌊⌊x⌋ / K^l⌋ in exact arithmetic), its index made in float;
// - a lane's march ends at a precomputed t (the projected radius or the image's edge) instead
//   of four bounds tests per read;
// - the tangent-plane test first runs a division-free form of its sign test with the least
//   tolerance, on n·r_S rebuilt by two multiply-adds; the exact test (the scalar code's
//   expressions, its rounding tolerance, square roots and divisions) runs only when a lane
//   passes it — on open surfaces no lane does.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/methods/pyramid_hbao/pyramid_hbao_simd.cpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <vector>

#include "core/base/parallel.h"
#include "core/base/simd-inl.h"
#include "core/base/simd_tiles.h"
#include "core/methods/pyramid_hbao/pyramid_hbao.h"
#include "core/methods/pyramid_hbao/pyramid_hbao_shared.h"
#include "core/sampling/blue_noise.h"
#include "core/sampling/random.h"

#ifndef AOLAB_PYRAMID_HBAO_SIMD_ONCE_
#define AOLAB_PYRAMID_HBAO_SIMD_ONCE_
namespace aolab::pyramid_simd {

// What the kernel reads of a frame.
struct Frame {
  const GatherPyramidLevel* levels;
  int level_count;
  const float* normals;  // prepared, 3 per pixel
  int width, height;
  CameraIntrinsics cam;
};

}  // namespace aolab::pyramid_simd
#endif  // AOLAB_PYRAMID_HBAO_SIMD_ONCE_

HWY_BEFORE_NAMESPACE();
namespace aolab::HWY_NAMESPACE {
namespace {
using pyramid_simd::Frame;
using Level = GatherPyramidLevel;

// pixel_random(seed, x, y, stream) for the pixels x0, x0 + 1, ... of row y, bit for bit, in
// two parts: PixelHash hashes the seed and the pixel once, PixelStream each stream of it
// (PixelRandom of simd-inl.h hashes all three for every stream).
HWY_INLINE VU PixelHash(DF df, std::uint32_t seed, int x0, int y) {
  const DU du;
  const std::uint32_t h0 = pcg_hash(seed ^ 0x9E3779B9u);
  auto h = hn::Xor(hn::Set(du, h0), hn::Add(hn::Set(du, std::uint32_t(x0)), hn::Iota(du, 0)));
  h = PcgHash(du, h);
  (void)df;
  return PcgHash(du, hn::Xor(h, hn::Set(du, std::uint32_t(y) * 0x85EBCA6Bu)));
}

HWY_INLINE VF PixelStream(DF df, VU pixel, std::uint32_t stream) {
  const DU du;
  const auto h = PcgHash(du, hn::Add(pixel, hn::Set(du, stream * 0xC2B2AE35u)));
  return hn::Mul(hn::ConvertTo(df, hn::BitCast(DI(), hn::ShiftRight<8>(h))),
                 hn::Set(df, kUnitRoundoff));
}

// sin θ and cos θ for 0 ≤ θ ≤ 4π (a direction's azimuth) to about an ulp: one reduction to
// r ∈ [−π/4, π/4] by a multiple q of π/2 (Cody and Waite's three-part π/2), shared by both,
// Cephes' minimax polynomials of sinf and cosf on r, and the quadrant q mod 4. Highway's Sin
// and Cos would each reduce θ on their own.
HWY_INLINE void SinCos(DF df, VF theta, VF& sin_theta, VF& cos_theta) {
  const DI di;
  const VF q = hn::Round(hn::Mul(theta, hn::Set(df, float(2.0 / std::numbers::pi))));
  VF r = hn::NegMulAdd(q, hn::Set(df, 1.57079637050628662109375f), theta);
  r = hn::NegMulAdd(q, hn::Set(df, -4.37113900018624283e-8f), r);
  r = hn::NegMulAdd(q, hn::Set(df, -1.71512451000597e-15f), r);
  const VF r2 = hn::Mul(r, r);
  const VF ps =
      hn::MulAdd(hn::MulAdd(hn::Set(df, -1.9515295891e-4f), r2, hn::Set(df, 8.3321608736e-3f)), r2,
                 hn::Set(df, -1.6666654611e-1f));
  const VF sin_r = hn::MulAdd(hn::Mul(ps, r2), r, r);
  const VF pc = hn::MulAdd(
      hn::MulAdd(hn::Set(df, 2.443315711809948e-5f), r2, hn::Set(df, -1.388731625493765e-3f)), r2,
      hn::Set(df, 4.166664568298827e-2f));
  const VF cos_r =
      hn::MulAdd(hn::Mul(pc, r2), r2, hn::NegMulAdd(hn::Set(df, 0.5f), r2, hn::Set(df, 1.0f)));
  // θ = q·π/2 + r: q odd swaps sin and cos; sin is negative for q mod 4 ∈ {2, 3}, cos for
  // q mod 4 ∈ {1, 2}.
  const VI qi = hn::ConvertTo(di, q);
  const MF odd = hn::RebindMask(df, hn::Ne(hn::And(qi, hn::Set(di, 1)), hn::Zero(di)));
  const VI sin_sign = hn::ShiftLeft<30>(hn::And(qi, hn::Set(di, 2)));
  const VI cos_sign = hn::ShiftLeft<30>(hn::And(hn::Add(qi, hn::Set(di, 1)), hn::Set(di, 2)));
  sin_theta = hn::Xor(hn::IfThenElse(odd, cos_r, sin_r), hn::BitCast(df, sin_sign));
  cos_theta = hn::Xor(hn::IfThenElse(odd, sin_r, cos_r), hn::BitCast(df, cos_sign));
}

// 1/v to about 1 ulp: the hardware estimate and one Newton step, a few cheap operations where
// a division is several times slower.
HWY_INLINE VF Reciprocal(DF df, VF v) {
  const VF r = hn::ApproximateReciprocal(v);
  return hn::Mul(r, hn::NegMulAdd(v, r, hn::Set(df, 2.0f)));
}

// The receiver P of each lane (horizon_receiver), and what its reads share.
struct Receiver {
  VF d, nx, ny, nz;
  VF xf, px, py, ox, oy;  // P's column, its pixel centre, their offsets from (cx, cy)
  VF n_r0;                // n · (P's view ray at depth 1)
  VF grazing;             // |r0| / |n·r0|
  VF dn;                  // d · (n·r0): tau = dn / (n·rs)
  VF dn_margin;           // dn / (1 + 12·2^-24): the prefilter's bound
  VF a, b;                // n·rs = n·r0 + a·qx + b·qy
  MF faces;               // n·r0 < 0
};

// More levels than a pyramid can have (sides below 2^24 and K ≥ 2 give at most 25).
constexpr int kMaxLevels = 40;

// What every read of a row shares.
struct RowConstants {
  VF inv_fx, inv_fy, cx, cy, width, height, radius2, inv_radius;
  float yf;  // the row's index as a float
  bool attenuate;
  float own_y[kMaxLevels];  // the row's texel ⌊y / K^l⌋ on each level
};

// The exact test and term of texel_contribution (pyramid_hbao.cpp) on the lanes `maybe` of a
// read whose centroid lies at P's pixel centre + (qx, qy), depth ds, on level l; the largest
// term into best.
HWY_INLINE void ExactRead(DF df, const Receiver& p, const RowConstants& k, MF maybe, VF qx, VF qy,
                          VF ds, float level, VF& best) {
  const VF zero = hn::Zero(df);
  // D = S − P without cancellation.
  const VF dd = hn::Sub(ds, p.d);
  const VF dx = hn::Mul(hn::MulAdd(qx, ds, hn::Mul(p.ox, dd)), k.inv_fx);
  const VF dy = hn::Neg(hn::Mul(hn::MulAdd(qy, ds, hn::Mul(p.oy, dd)), k.inv_fy));
  const VF r2 = hn::MulAdd(dx, dx, hn::MulAdd(dy, dy, hn::Mul(dd, dd)));
  // Within R (strictly with eq. 7's W, which is 0 at R) and not P itself; NaN fails.
  const MF within = k.attenuate ? hn::Lt(r2, k.radius2) : hn::Le(r2, k.radius2);
  MF counts = hn::And(maybe, hn::And(within, hn::Ne(r2, zero)));
  if (hn::AllFalse(df, counts)) return;
  // Above the tangent plane, as the scalar code: the plane meets the sample's ray rs at
  // depth tau = d (n·r0)/(n·rs), with the rounding tolerance.
  const VF rsx = hn::Mul(hn::Sub(hn::Add(qx, p.px), k.cx), k.inv_fx);
  const VF rsy = hn::Neg(hn::Mul(hn::Sub(hn::Add(qy, p.py), k.cy), k.inv_fy));
  const VF n_rs = hn::Sub(hn::MulAdd(p.nx, rsx, hn::Mul(p.ny, rsy)), p.nz);
  const VF tau = hn::Div(p.dn, n_rs);
  const MF hits = hn::And(hn::And(hn::Lt(n_rs, zero), hn::Gt(tau, zero)), hn::IsFinite(tau));
  counts = hn::AndNot(hn::AndNot(hn::Gt(tau, ds), hits), counts);
  if (hn::AllFalse(df, counts)) return;
  const VF grazing_s = hn::Div(
      hn::Sqrt(hn::MulAdd(rsx, rsx, hn::MulAdd(rsy, rsy, hn::Set(df, 1.0f)))), hn::Abs(n_rs));
  const VF ulps = hn::MulAdd(hn::Set(df, kPyramidHbaoNormalUlps), hn::Add(p.grazing, grazing_s),
                             hn::Set(df, kPyramidHbaoDepthUlps + kPyramidHbaoLevelUlps * level));
  const VF tol = hn::Mul(
      hn::Mul(hn::Set(df, kUnitRoundoff), hn::Max(ds, hn::IfThenElse(hits, tau, ds))), ulps);
  const VF gap =
      hn::Sub(hn::IfThenElse(hits, tau, hn::Set(df, std::numeric_limits<float>::infinity())), ds);
  counts = hn::And(counts, hn::Gt(gap, tol));
  if (hn::AllFalse(df, counts)) return;
  // Eq. 8's term W(r)·sin α.
  const VF r = hn::Sqrt(hn::IfThenElse(counts, r2, hn::Set(df, 1.0f)));
  const VF n_d = hn::Sub(hn::MulAdd(p.nx, dx, hn::Mul(p.ny, dy)), hn::Mul(p.nz, dd));
  const VF sin_alpha = hn::Min(hn::Max(hn::Div(n_d, r), zero), hn::Set(df, 1.0f));
  const VF term = k.attenuate
                      ? hn::Mul(hn::NegMulAdd(r, k.inv_radius, hn::Set(df, 1.0f)), sin_alpha)
                      : sin_alpha;
  best = hn::IfThenElse(counts, hn::Max(best, term), best);
}

// The state of one direction's march on every lane.
struct March {
  VF ux, uy;  // the unit image direction
  VF end;     // the march ends past t = end: the projected radius, or where it leaves the image
  VF t;       // distance marched from P's centre, pixels
  VF best;    // eq. 8's max so far
};

// The array index of texel (tx, ty) (GatherPyramidLevel::at). With kFloatIndex (levels of
// fewer than 2^23 texels with their border) the index is exact in float and becomes an int
// by the bits of its sum with 2^23 (two cheap operations, where a conversion takes five);
// otherwise by converting tx and ty.
template <bool kFloatIndex>
HWY_INLINE VI TexelIndex(DF df, VF tx, VF ty, VF stride_f, VF offset_f, VI stride_i, VI offset_i) {
  const DI di;
  if constexpr (kFloatIndex) {
    // offset_f = 2^23 + stride + 1: the sum holds the index in its low bits.
    return hn::Sub(hn::BitCast(di, hn::Add(hn::MulAdd(ty, stride_f, tx), offset_f)),
                   hn::BitCast(di, hn::Set(df, 8388608.0f)));
  } else {
    (void)df, (void)stride_f, (void)offset_f;
    return hn::Add(hn::Add(hn::Mul(hn::ConvertTo(di, ty), stride_i), hn::ConvertTo(di, tx)),
                   offset_i);
  }
}

// The exact test of the lanes `maybe` of a read on level l ≥ 1 (ExactRead), first reading
// the centroid of the lanes whose texel is marked.
HWY_NOINLINE void ExactCoarseRead(DF df, const Level& level, const Receiver& p,
                                  const RowConstants& k, MF maybe, VI texel, VF g, VF qx, VF qy,
                                  float l, VF& best) {
  const MF marked = hn::And(maybe, hn::Lt(g, hn::Zero(df)));
  if (!hn::AllFalse(df, marked)) {
    qx = hn::IfThenElse(marked, hn::Sub(hn::GatherIndex(df, level.cx, texel), p.px), qx);
    qy = hn::IfThenElse(marked, hn::Sub(hn::GatherIndex(df, level.cy, texel), p.py), qy);
  }
  ExactRead(df, p, k, maybe, qx, qy, hn::Abs(g), l, best);
}

// The S reads of level l (kBase: level 0) of march_direction on every lane; false once every
// lane's march has ended.
template <bool kBase, bool kFloatIndex>
HWY_INLINE bool MarchLevel(DF df, const Level& level, int l, int samples, VF m, const Receiver& p,
                           const RowConstants& k, March& a) {
  const DI di;
  const VF zero = hn::Zero(df);
  const float scale_f = float(level.scale);
  const VF scale = hn::Set(df, scale_f);
  const VF step = hn::Mul(m, scale);
  // P's column ⌊n / K^l⌋ as ⌊(n + ½)·(1/K^l)⌋: (n + ½)/K^l lies at least ½/K^l
  // from an integer, farther than the product's rounding below 2^22 (kPyramidHbaoSimdMaxSide).
  const VF inv_scale = hn::Set(df, 1.0f / scale_f);
  const VF half_inv_scale = hn::Set(df, 0.5f / scale_f);
  // The centroid of a whole footprint, K^l·(X + ½), less P's pixel centre.
  const VF centre_x = hn::Sub(hn::Set(df, 0.5f * scale_f), p.px);
  const VF centre_y = hn::Sub(hn::Set(df, 0.5f * scale_f), p.py);
  const VF stride_f = hn::Set(df, float(level.stride));
  const VF offset_f = hn::Set(df, 8388608.0f + float(level.stride + 1));
  const VI stride_i = hn::Set(di, level.stride);
  const VI offset_i = hn::Set(di, level.stride + 1);
  // P's own texel on this level, which the march skips. (On level 0 it needs no test: its
  // read is P itself, r = 0, which the exact test rejects, and the prefilter already does.)
  VI own = hn::Zero(di);
  if (!kBase) {
    const VF own_x = hn::Floor(hn::MulAdd(p.xf, inv_scale, half_inv_scale));
    const VF own_y = hn::Set(df, k.own_y[l]);
    own = TexelIndex<kFloatIndex>(df, own_x, own_y, stride_f, offset_f, stride_i, offset_i);
  }
  // A read's position in texels of this level, (P + t·u)/K^l: the same texel as the scalar
  // code's ⌊⌊x⌋ / K^l⌋ (equal in exact arithmetic; the rounding differs only for a read
  // within an ulp of a texel edge).
  const VF px_l = kBase ? p.px : hn::Mul(p.px, inv_scale);
  const VF py_l = kBase ? p.py : hn::Mul(p.py, inv_scale);
  const VF ux_l = kBase ? a.ux : hn::Mul(a.ux, inv_scale);
  const VF uy_l = kBase ? a.uy : hn::Mul(a.uy, inv_scale);
  // n·rs of texel (tx, ty) as a·tx + b·ty + c (the read's centroid less P's centre is
  // tx − x on level 0, tx·K^l + centre_x on a coarser one; likewise y).
  const VF ya = hn::Set(df, k.yf);
  const VF a_l = kBase ? p.a : hn::Mul(p.a, scale);
  const VF b_l = kBase ? p.b : hn::Mul(p.b, scale);
  const VF c_l = kBase ? hn::NegMulAdd(p.a, p.xf, hn::NegMulAdd(p.b, ya, p.n_r0))
                       : hn::MulAdd(p.a, centre_x, hn::MulAdd(p.b, centre_y, p.n_r0));
  for (int i = 0; i < samples; ++i) {
    a.t = hn::Add(a.t, step);
    // Past the projected radius, or out of the image: the lane's march ends (t only grows).
    const MF alive = hn::Le(a.t, a.end);
    if (hn::AllFalse(df, alive)) return false;
    // An ended lane reads at its last t, inside the image.
    const VF t = hn::Min(a.t, a.end);
    const VF tx = hn::Floor(hn::MulAdd(t, ux_l, px_l));
    const VF ty = hn::Floor(hn::MulAdd(t, uy_l, py_l));
    const VI texel = TexelIndex<kFloatIndex>(df, tx, ty, stride_f, offset_f, stride_i, offset_i);
    const VF g = hn::GatherIndex(df, level.depth, texel);
    const MF live = kBase ? alive : hn::AndNot(hn::RebindMask(df, hn::Eq(texel, own)), alive);
    // The prefilter: where the sample's ray meets the tangent plane in front of the camera
    // (n·rs < 0 and n·r0 < 0, d > 0), the exact test needs tau > ds·(1 + 16·2^-24) (its
    // tolerance is at least 2^-24·ds·(8 + 4·(1 + 1)), each g ≥ 1), i.e.
    // d·(n·r0) < ds·(n·rs)·(1 + 16·2^-24). 12 of the 16 ulps here, the rest for the rounding
    // of n·rs rebuilt by two multiply-adds: a lane it drops would fail the exact test, and on
    // an open surface, where tau and ds agree to a few ulps, it drops every one. Where n·rs ≥ 0
    // the comparison holds by itself (its left side is negative), and where n·r0 ≥ 0 the bound
    // is −inf: every read goes to the exact test. Background (NaN) fails. On a coarser level
    // the centroid is the footprint's centre, except where the texel is marked (g < 0), whose
    // lanes always go to the exact test, which reads the centroid.
    const VF n_rs = hn::MulAdd(a_l, tx, hn::MulAdd(b_l, ty, c_l));
    MF maybe = hn::Lt(p.dn_margin, hn::Mul(g, n_rs));
    if (!kBase) maybe = hn::Or(maybe, hn::Lt(g, zero));  // marked
    maybe = hn::And(live, maybe);
    if (HWY_UNLIKELY(!hn::AllFalse(df, maybe))) {
      if (kBase)
        ExactRead(df, p, k, maybe, hn::Sub(tx, p.xf), hn::Sub(ty, ya), g, 0.0f, a.best);
      else
        ExactCoarseRead(df, level, p, k, maybe, texel, g, hn::MulAdd(tx, scale, centre_x),
                        hn::MulAdd(ty, scale, centre_y), float(l), a.best);
    }
  }
  return true;
}

// march_direction's set-up on every lane: the direction (c, sn) as an image direction and the
// t past which its march ends.
HWY_INLINE March StartDirection(DF df, const Frame& f, const PyramidHbaoSettings& s,
                                const Receiver& p, const RowConstants& k, MF geometry, VF c,
                                VF sn) {
  const VF zero = hn::Zero(df);
  const VF inf = hn::Set(df, std::numeric_limits<float>::infinity());
  // The azimuth as an image direction (rows go down) and the projected radius along it.
  const VF ex = hn::Mul(c, hn::Set(df, f.cam.fx));
  const VF ey = hn::Neg(hn::Mul(sn, hn::Set(df, f.cam.fy)));
  const VF e_len = hn::Sqrt(hn::MulAdd(ex, ex, hn::Mul(ey, ey)));
  March a;
  // Divisions, as the scalar code: a read's position then differs from its only by the
  // rounding of sin and cos and of the fused t·u + P.
  a.ux = hn::Div(ex, e_len), a.uy = hn::Div(ey, e_len);
  const VF reach = hn::Div(hn::Mul(hn::Set(df, s.radius), e_len), p.d);
  // Where the line leaves the image: x = 0 or x = W, y = 0 or y = H (inf along an axis it
  // does not cross). The scalar march tests each read's position instead; the two differ only
  // for a read within rounding of the image's edge, which then reads the border (background)
  // or is not read.
  const VF exit_x =
      hn::Mul(hn::IfThenElse(hn::Gt(a.ux, zero), hn::Sub(k.width, p.px), hn::Neg(p.px)),
              Reciprocal(df, a.ux));
  const VF exit_y =
      hn::Mul(hn::IfThenElse(hn::Gt(a.uy, zero), hn::Sub(k.height, p.py), hn::Neg(p.py)),
              Reciprocal(df, a.uy));
  // Background (NaN reach) and the tail's lanes end before the first read.
  a.end = hn::IfThenElse(geometry,
                         hn::Min(reach, hn::Min(hn::IfThenElse(hn::IsNaN(exit_x), inf, exit_x),
                                                hn::IfThenElse(hn::IsNaN(exit_y), inf, exit_y))),
                         hn::Set(df, -1.0f));
  a.end = hn::IfThenElse(hn::IsNaN(reach), hn::Set(df, -1.0f), a.end);
  a.t = zero, a.best = zero;
  return a;
}

// march_direction's reads on every lane, from StartDirection's a with start multiplier m:
// eq. 8's term max_i W(r_i)·sin α_i of the direction.
template <bool kFloatIndex>
HWY_INLINE VF MarchDirection(DF df, const Frame& f, const PyramidHbaoSettings& s, const Receiver& p,
                             const RowConstants& k, VF m, March a) {
  if (f.level_count > 0 && MarchLevel<true, kFloatIndex>(df, f.levels[0], 0, s.samples, m, p, k, a))
    for (int l = 1; l < f.level_count; ++l)
      if (!MarchLevel<false, kFloatIndex>(df, f.levels[l], l, s.samples, m, p, k, a)) break;
  return a.best;
}

HWY_INLINE RowConstants MakeRowConstants(DF df, const Frame& f, const PyramidHbaoSettings& s,
                                         int y) {
  RowConstants k;
  const float inv_fx = 1.0f / f.cam.fx, inv_fy = 1.0f / f.cam.fy;
  k.inv_fx = hn::Set(df, inv_fx), k.inv_fy = hn::Set(df, inv_fy);
  k.cx = hn::Set(df, f.cam.cx), k.cy = hn::Set(df, f.cam.cy);
  k.width = hn::Set(df, float(f.width)), k.height = hn::Set(df, float(f.height));
  k.radius2 = hn::Set(df, s.radius * s.radius);
  k.inv_radius = hn::Set(df, 1.0f / s.radius);
  k.yf = float(y);
  k.attenuate = s.attenuation == int(PyramidHbaoAttenuation::Linear);
  for (int l = 0; l < f.level_count && l < kMaxLevels; ++l)
    k.own_y[l] = float(y / f.levels[l].scale);
  return k;
}

// The row's blue-noise rotations, pyramid_hbao_directions' values (the texture's value plus the
// global rotation, modulo 1), twice over: the rotations of the pixels x0 … x0 + Lanes − 1 are
// then Lanes consecutive values from ((x0 + shift_x) mod 32) (one load, where a lane-by-lane
// loop stored into an array that a vector load then read, a stalled store forwarding).
struct NoiseRow {
  static constexpr int kSize = kBlueNoiseSize;
  int shift_x;
  HWY_ALIGN float rotation[2 * kSize + hn::MaxLanes(DF())];

  NoiseRow(const PyramidHbaoSettings& s, int y) {
    // pyramid_hbao_directions' blue-noise shift and global rotation: once per row.
    const std::uint32_t noise_hash = pcg_hash(std::uint32_t(s.seed) ^ 0x6A09E667u);
    const float global = float(pcg_hash(noise_hash) >> 8) * kUnitRoundoff;
    shift_x = int(noise_hash & 31u);
    const int shift_y = int((noise_hash >> 5) & 31u);
    const auto& ranks = blue_noise_ranks();
    for (int i = 0; i < 2 * kSize + int(hn::Lanes(DF())); ++i) {
      float r = 0.0f;
      if (s.rotation) {
        r = blue_noise_value(ranks, i % kSize, y + shift_y) + global;
        if (r >= 1.0f) r -= 1.0f;
      }
      rotation[i] = r;
    }
  }
  // The rotations of the pixels x0 … x0 + Lanes − 1.
  HWY_INLINE VF At(DF df, int x0) const { return hn::LoadU(df, rotation + (x0 + shift_x) % kSize); }
};

// The depths and normals of pixels x0 … x0 + Lanes − 1 of the rows (count of them in the row;
// the lanes past it repeat its last pixel).
HWY_INLINE void LoadPixels(DF df, const float* depth_row, const float* normal_row, int x0,
                           int count, Receiver& p) {
  const int lanes = int(hn::Lanes(df));
  if (count == lanes) {
    // Whole vectors straight from the rows (the normals de-interleaved).
    p.d = hn::LoadU(df, depth_row + x0);
    hn::LoadInterleaved3(df, normal_row + 3 * std::size_t(x0), p.nx, p.ny, p.nz);
  } else {
    HWY_ALIGN float lane[4][hn::MaxLanes(df)];
    for (int i = 0; i < lanes; ++i) {
      const std::size_t at = std::size_t(x0 + std::min(i, count - 1));
      lane[0][i] = depth_row[at];
      for (int c = 0; c < 3; ++c) lane[1 + c][i] = normal_row[3 * at + c];
    }
    p.d = hn::Load(df, lane[0]);
    p.nx = hn::Load(df, lane[1]), p.ny = hn::Load(df, lane[2]), p.nz = hn::Load(df, lane[3]);
  }
}

// horizon_receiver on every lane of P's loaded depth and normal; a tail lane repeats the row's
// last pixel at its own x (dropped).
HWY_INLINE void SetUpReceiver(DF df, const Frame& f, const RowConstants& k, int x0, int y,
                              Receiver& p) {
  const float py = float(y) + 0.5f;
  p.xf = hn::Iota(df, float(x0));
  p.px = PixelCentres(df, x0), p.py = hn::Set(df, py);
  p.ox = hn::Sub(p.px, k.cx), p.oy = hn::Set(df, py - f.cam.cy);
  const VF r0x = hn::Mul(p.ox, k.inv_fx), r0y = hn::Neg(hn::Mul(p.oy, k.inv_fy));
  p.n_r0 = hn::Sub(hn::MulAdd(p.nx, r0x, hn::Mul(p.ny, r0y)), p.nz);
  p.grazing = hn::Div(hn::Sqrt(hn::MulAdd(r0x, r0x, hn::MulAdd(r0y, r0y, hn::Set(df, 1.0f)))),
                      hn::Abs(p.n_r0));
  p.dn = hn::Mul(p.d, p.n_r0);
  p.faces = hn::Lt(p.n_r0, hn::Zero(df));
  p.dn_margin =
      hn::IfThenElse(p.faces, hn::Mul(p.dn, hn::Set(df, 1.0f / (1.0f + 12.0f * kUnitRoundoff))),
                     hn::Set(df, -std::numeric_limits<float>::infinity()));
  p.a = hn::Mul(p.nx, k.inv_fx), p.b = hn::Neg(hn::Mul(p.ny, k.inv_fy));
}

// Σ over the directions of every lane's largest term (pyramid_hbao_pixel's sum). The set-up of
// kBatch directions first, then their marches: the set-ups are independent chains of latency
// (hash, sine and cosine, square root, divisions) that overlap one another, where set up one by
// one each would wait behind the previous march's last read and delay its own first one.
HWY_INLINE VF DirectionsOcclusion(DF df, const Frame& f, const PyramidHbaoSettings& s,
                                  const Receiver& p, const RowConstants& k, MF geometry,
                                  VU pixel_hash, VF rotation, bool float_index) {
  const float sector = float(2.0 * std::numbers::pi / s.directions);
  VF occlusion = hn::Zero(df);
  constexpr int kBatch = 8;
  March start[kBatch];
  VF start_m[kBatch];
  for (int d0 = 0; d0 < s.directions; d0 += kBatch) {
    const int batch = std::min(kBatch, s.directions - d0);
    for (int j = 0; j < batch; ++j) {
      const int dir = d0 + j;
      // pyramid_hbao_directions: θ from the lane's rotation and random place in the sector,
      // and the start multiplier m.
      const VF place =
          s.random_directions ? PixelStream(df, pixel_hash, 2u * std::uint32_t(dir)) : hn::Zero(df);
      const VF theta =
          hn::Mul(hn::Set(df, sector), hn::Add(hn::Add(hn::Set(df, float(dir)), rotation), place));
      const VF m = s.random_start
                       ? hn::Add(hn::Set(df, kPyramidHbaoStartMin),
                                 hn::Mul(hn::Set(df, kPyramidHbaoStartMax - kPyramidHbaoStartMin),
                                         PixelStream(df, pixel_hash, 2u * std::uint32_t(dir) + 1u)))
                       : hn::Set(df, 1.0f);
      VF c, sn;
      SinCos(df, theta, sn, c);
      start[j] = StartDirection(df, f, s, p, k, geometry, c, sn);
      start_m[j] = m;
    }
    // The terms summed in the order of the directions, as before.
    for (int j = 0; j < batch; ++j)
      occlusion = hn::Add(
          occlusion, float_index ? MarchDirection<true>(df, f, s, p, k, start_m[j], start[j])
                                 : MarchDirection<false>(df, f, s, p, k, start_m[j], start[j]));
  }
  return occlusion;
}

}  // namespace

// Pixels [x_begin, x_end) of row y of Pyramid HBAO into out (the row): pyramid_hbao_pixel
// on Lanes pixels at a time.
void PyramidHbaoSpan(const Frame& f, const PyramidHbaoSettings& s, int y, int x_begin, int x_end,
                     float* HWY_RESTRICT out) {
  const DF df;
  const RowConstants k = MakeRowConstants(df, f, s, y);
  const Level& base = f.levels[0];
  const float* depth_row = base.depth + base.at(0, y);
  const float* normal_row = f.normals + 3 * std::size_t(y) * f.width;
  // Level 0 is the largest.
  const bool float_index =
      std::size_t(base.stride) * std::size_t(base.height + 2) < (std::size_t(1) << 23);
  const NoiseRow noise(s, y);
  ForEachSpanVector(df, x_begin, x_end, [&](int x0, int count) {
    Receiver p;
    LoadPixels(df, depth_row, normal_row, x0, count, p);
    // Background is NaN; the tail's lanes (repeating the row's last pixel) are not marched.
    const MF geometry =
        hn::And(hn::Eq(p.d, p.d), hn::Lt(hn::Iota(df, 0.0f), hn::Set(df, float(count))));
    VF result = hn::Set(df, 1.0f);
    if (!hn::AllFalse(df, geometry)) {
      SetUpReceiver(df, f, k, x0, y, p);
      const VF occlusion =
          DirectionsOcclusion(df, f, s, p, k, geometry, PixelHash(df, std::uint32_t(s.seed), x0, y),
                              noise.At(df, x0), float_index);
      const VF ao =
          hn::Sub(hn::Set(df, 1.0f), hn::Div(occlusion, hn::Set(df, float(s.directions))));
      result =
          hn::IfThenElse(geometry, hn::Min(hn::Max(ao, hn::Zero(df)), hn::Set(df, 1.0f)), result);
    }
    StoreRowPart(df, result, count, out + x0);
  });
}

}  // namespace aolab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace aolab {

HWY_EXPORT(PyramidHbaoSpan);

Image pyramid_hbao_simd(const GatherPyramid& pyramid, const float* normals,
                        const CameraIntrinsics& cam, const PyramidHbaoSettings& s, int threads,
                        Progress* progress) {
  const GatherPyramidLevel& base = pyramid.level(0);
  const pyramid_simd::Frame frame{pyramid.data(), pyramid.levels(), normals,
                                  base.width,     base.height,      cam};
  return image_from_simd_tiles(base.width, base.height, threads, progress,
                               [&](int y, int x0, int x1, float* out) {
                                 HWY_DYNAMIC_DISPATCH(PyramidHbaoSpan)(frame, s, y, x0, x1, out);
                               });
}

}  // namespace aolab
#endif  // HWY_ONCE
