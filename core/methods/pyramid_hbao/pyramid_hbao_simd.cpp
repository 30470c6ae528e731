// Pyramid HBAO's SIMD kernel: the scalar per-pixel code of pyramid_hbao.cpp (the oracle it is
// tested against) on Lanes consecutive pixels of a row at once, compiled by Highway for every
// target and dispatched at run time. Every setting is supported; each lane follows the scalar
// pixel's steps (its own directions and start steps, the same reads on the same levels, the
// same tests), so the two differ only by float rounding (FMA, Highway's sin/cos).
//
// What it does differently (docs/methods/pyramid_hbao.md, "SIMD kernel"):
// - the levels are laid out for gathers: level 0 is read in place (the depth of the pyramid's
//   texels, a stride of 3 floats); every coarser level is split into arrays of depth and of
//   centroid x and y, and a texel's depth has its sign bit set where its centroid is not its
//   footprint's centre (the image border or background cut the footprint). A read then gathers
//   one float, and computes the centroid from the texel's coordinates; the two centroid
//   gathers run only when a lane meets a marked texel;
// - the texel ⌊⌊x⌋ / K^l⌋ of a read is a float multiply and floor, exact below
//   kPyramidHbaoSimdMaxSide;
// - the tangent-plane test first runs a division-free form of its sign test with the least
//   tolerance, on n·r_S rebuilt from P's n·r_P by two multiply-adds; the exact test (the
//   scalar code's expressions, its rounding tolerance, square roots and divisions) runs only
//   when a lane passes it — on open surfaces no lane does.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/methods/pyramid_hbao/pyramid_hbao_simd.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <vector>

#include "core/base/parallel.h"
#include "core/base/simd-inl.h"
#include "core/methods/pyramid_hbao/pyramid_hbao.h"
#include "core/sampling/blue_noise.h"
#include "core/sampling/random.h"

#ifndef AOLAB_PYRAMID_HBAO_SIMD_TYPES_
#define AOLAB_PYRAMID_HBAO_SIMD_TYPES_
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
#endif  // AOLAB_PYRAMID_HBAO_SIMD_TYPES_

HWY_BEFORE_NAMESPACE();
namespace aolab::HWY_NAMESPACE {
namespace {
namespace hn = hwy::HWY_NAMESPACE;
using DF = hn::ScalableTag<float>;
using DI = hn::RebindToSigned<DF>;
using VF = hn::Vec<DF>;
using VI = hn::Vec<DI>;
using MF = hn::Mask<DF>;
using pyramid_simd::Frame;
using Level = GatherPyramidLevel;

constexpr float kUnitRoundoff = 1.0f / 16777216.0f;  // 2^-24

// The receiver P of each lane (hbao_receiver), and what its reads share.
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

// What every read of a row shares.
struct RowConstants {
  VF inv_fx, inv_fy, cx, cy, width, height, radius2, inv_radius;
  float yf;  // the row's index as a float
  bool attenuate;
};

// The exact test and term of texel_contribution (pyramid_hbao.cpp) on the lanes `maybe` of a
// read whose centroid lies at P's pixel centre + (qx, qy), depth ds, on level l; the largest
// term into best.
HWY_INLINE void ExactRead(DF df, const Receiver& p, const RowConstants& k, MF maybe, VF qx,
                          VF qy, VF ds, float level, VF& best) {
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
  const VF grazing_s =
      hn::Div(hn::Sqrt(hn::MulAdd(rsx, rsx, hn::MulAdd(rsy, rsy, hn::Set(df, 1.0f)))),
              hn::Abs(n_rs));
  const VF ulps = hn::MulAdd(hn::Set(df, kPyramidHbaoNormalUlps), hn::Add(p.grazing, grazing_s),
                             hn::Set(df, kPyramidHbaoDepthUlps + kPyramidHbaoLevelUlps * level));
  const VF tol =
      hn::Mul(hn::Mul(hn::Set(df, kUnitRoundoff), hn::Max(ds, hn::IfThenElse(hits, tau, ds))), ulps);
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
  VF ux, uy;   // the unit image direction
  VF reach;    // the projected radius along it, pixels
  VF t;        // distance marched from P's centre, pixels
  VF best;     // eq. 8's max so far
  MF alive;    // still marching
};

// Texel indices from float coordinates: with kFloatIndex (levels of fewer than 2^23 texels)
// Y·width + X is exact in float and becomes an int by the bits of its sum with 2^23 (two
// cheap operations, where a conversion takes five); otherwise by converting X and Y.
template <bool kFloatIndex>
HWY_INLINE VI TexelIndex(DF df, VF tx, VF ty, VF width_f, VI width_i) {
  const DI di;
  if constexpr (kFloatIndex) {
    const VF magic = hn::Set(df, 8388608.0f);  // 2^23: its sum with n < 2^23 holds n's bits
    return hn::Sub(hn::BitCast(di, hn::Add(hn::MulAdd(ty, width_f, tx), magic)),
                   hn::BitCast(di, magic));
  } else {
    (void)df, (void)width_f;
    return hn::Add(hn::Mul(hn::ConvertTo(di, ty), width_i), hn::ConvertTo(di, tx));
  }
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
  // ⌊n / K^l⌋ of an integer n ≥ 0 as ⌊(n + ½)·(1/K^l)⌋: (n + ½)/K^l lies at least ½/K^l
  // from an integer, farther than the product's rounding below 2^22 (kPyramidHbaoSimdMaxSide).
  const VF inv_scale = hn::Set(df, 1.0f / scale_f);
  const VF half_inv_scale = hn::Set(df, 0.5f / scale_f);
  // P's texel on this level.
  const VF own_x = kBase ? p.xf : hn::Floor(hn::MulAdd(p.xf, inv_scale, half_inv_scale));
  const VF own_y = hn::Set(df, kBase ? k.yf : float(int(k.yf) / level.scale));
  // The centroid of a whole footprint, K^l·(X + ½), less P's pixel centre.
  const VF centre_x = hn::Sub(hn::Set(df, 0.5f * scale_f), p.px);
  const VF centre_y = hn::Sub(hn::Set(df, 0.5f * scale_f), p.py);
  const VF width_f = hn::Set(df, float(level.width));
  const VI width_i = hn::Set(di, level.width);
  for (int i = 0; i < samples; ++i) {
    a.t = hn::Add(a.t, step);
    // Past the projected radius, or out of the image: the lane's march ends (t and the
    // position only grow along the line, so it never comes back). NaN fails.
    const VF sx = hn::MulAdd(a.t, a.ux, p.px), sy = hn::MulAdd(a.t, a.uy, p.py);
    a.alive = hn::And(a.alive, hn::And(hn::Le(a.t, a.reach),
                                       hn::And(hn::And(hn::Ge(sx, zero), hn::Lt(sx, k.width)),
                                               hn::And(hn::Ge(sy, zero), hn::Lt(sy, k.height)))));
    if (hn::AllFalse(df, a.alive)) return false;
    VF tx = hn::Floor(hn::IfThenElseZero(a.alive, sx));
    VF ty = hn::Floor(hn::IfThenElseZero(a.alive, sy));
    if (!kBase) {
      tx = hn::Floor(hn::MulAdd(tx, inv_scale, half_inv_scale));
      ty = hn::Floor(hn::MulAdd(ty, inv_scale, half_inv_scale));
    }
    const MF live = hn::AndNot(hn::And(hn::Eq(tx, own_x), hn::Eq(ty, own_y)), a.alive);
    const VI texel = TexelIndex<kFloatIndex>(df, tx, ty, width_f, width_i);
    const VF g = hn::GatherIndex(df, level.depth, texel);
    VF ds, qx, qy;
    if (kBase) {
      // Level 0: the texel is P's pixel + (qx, qy), its centroid the pixel centre.
      ds = g;
      qx = hn::Sub(tx, p.xf);
      qy = hn::Sub(ty, hn::Set(df, k.yf));
    } else {
      ds = hn::Abs(g);
      qx = hn::MulAdd(tx, scale, centre_x);
      qy = hn::MulAdd(ty, scale, centre_y);
      const MF marked = hn::And(live, hn::Lt(g, zero));
      if (HWY_UNLIKELY(!hn::AllFalse(df, marked))) {
        qx = hn::IfThenElse(marked, hn::Sub(hn::GatherIndex(df, level.cx, texel), p.px), qx);
        qy = hn::IfThenElse(marked, hn::Sub(hn::GatherIndex(df, level.cy, texel), p.py), qy);
      }
    }
    // The prefilter: where the sample's ray meets the tangent plane in front of the camera
    // (n·rs < 0 and n·r0 < 0, d > 0), the exact test needs tau > ds·(1 + 16·2^-24) (its
    // tolerance is at least 2^-24·ds·(8 + 4·(1 + 1)), each g ≥ 1), i.e.
    // d·(n·r0) < ds·(n·rs)·(1 + 16·2^-24). 12 of the 16 ulps here, the rest for the rounding
    // of n·rs rebuilt by two multiply-adds: a lane it drops would fail the exact test, and on
    // an open surface, where tau and ds agree to a few ulps, it drops every one. Where n·rs ≥ 0
    // the comparison holds by itself (its left side is negative), and where n·r0 ≥ 0 the bound
    // is −inf: every read goes to the exact test.
    const VF n_rs = hn::MulAdd(p.a, qx, hn::MulAdd(p.b, qy, p.n_r0));
    const MF maybe = hn::And(live, hn::Lt(p.dn_margin, hn::Mul(ds, n_rs)));
    if (HWY_UNLIKELY(!hn::AllFalse(df, maybe)))
      ExactRead(df, p, k, maybe, qx, qy, ds, float(l), a.best);
  }
  return true;
}

// march_direction on every lane: eq. 8's term max_i W(r_i)·sin α_i of the direction
// (c, sn) with start multiplier m.
template <bool kFloatIndex>
HWY_INLINE VF MarchDirection(DF df, const Frame& f, const PyramidHbaoSettings& s,
                             const Receiver& p, const RowConstants& k, MF geometry, VF c, VF sn,
                             VF m) {
  // The azimuth as an image direction (rows go down) and the projected radius along it.
  const VF ex = hn::Mul(c, hn::Set(df, f.cam.fx));
  const VF ey = hn::Neg(hn::Mul(sn, hn::Set(df, f.cam.fy)));
  const VF e_len = hn::Sqrt(hn::MulAdd(ex, ex, hn::Mul(ey, ey)));
  March a;
  a.ux = hn::Div(ex, e_len), a.uy = hn::Div(ey, e_len);
  a.reach = hn::Div(hn::Mul(hn::Set(df, s.radius), e_len), p.d);
  a.t = hn::Zero(df), a.best = hn::Zero(df);
  a.alive = geometry;
  if (f.level_count < 1 ||
      !MarchLevel<true, kFloatIndex>(df, f.levels[0], 0, s.samples, m, p, k, a))
    return a.best;
  for (int l = 1; l < f.level_count; ++l)
    if (!MarchLevel<false, kFloatIndex>(df, f.levels[l], l, s.samples, m, p, k, a)) break;
  return a.best;
}

}  // namespace

// Pixels [x_begin, x_end) of row y of Pyramid HBAO into out (the row): pyramid_hbao_pixel
// on Lanes pixels at a time.
void PyramidHbaoSpan(const Frame& f, const PyramidHbaoSettings& s, int y, int x_begin, int x_end,
                     float* HWY_RESTRICT out) {
  const DF df;
  const int w = f.width;
  RowConstants k;
  const float inv_fx = 1.0f / f.cam.fx, inv_fy = 1.0f / f.cam.fy;
  k.inv_fx = hn::Set(df, inv_fx), k.inv_fy = hn::Set(df, inv_fy);
  k.cx = hn::Set(df, f.cam.cx), k.cy = hn::Set(df, f.cam.cy);
  k.width = hn::Set(df, float(w)), k.height = hn::Set(df, float(f.height));
  k.radius2 = hn::Set(df, s.radius * s.radius);
  k.inv_radius = hn::Set(df, 1.0f / s.radius);
  k.yf = float(y);
  k.attenuate = s.attenuation == int(PyramidHbaoAttenuation::Linear);
  const Level& base = f.levels[0];
  const float* depth_row = base.depth + std::size_t(y) * w;
  const float* normal_row = f.normals + 3 * std::size_t(y) * w;
  const float py = float(y) + 0.5f;
  const float sector = float(2.0 * std::numbers::pi / s.directions);
  const auto seed = std::uint32_t(s.seed);
  // pyramid_hbao_directions' blue-noise shift and global rotation: once per row.
  const std::uint32_t noise_hash = pcg_hash(seed ^ 0x6A09E667u);
  const float global = float(pcg_hash(noise_hash) >> 8) * kUnitRoundoff;
  const int shift_x = int(noise_hash & 31u), shift_y = int((noise_hash >> 5) & 31u);
  const auto& ranks = blue_noise_ranks();
  const int lanes = int(hn::Lanes(df));
  // Level 0 is the largest.
  const bool float_index = std::size_t(w) * std::size_t(f.height) < (std::size_t(1) << 23);

  ForEachSpanVector(df, x_begin, x_end, [&](int x0, int count) {
    Receiver p;
    HWY_ALIGN float lane[4][hn::MaxLanes(df)];
    for (int i = 0; i < lanes; ++i) {
      const std::size_t at = std::size_t(x0 + std::min(i, count - 1));
      lane[0][i] = depth_row[at];
      for (int c = 0; c < 3; ++c) lane[1 + c][i] = normal_row[3 * at + c];
    }
    p.d = hn::Load(df, lane[0]);
    p.nx = hn::Load(df, lane[1]), p.ny = hn::Load(df, lane[2]), p.nz = hn::Load(df, lane[3]);
    const MF geometry = hn::Eq(p.d, p.d);  // background is NaN
    VF result = hn::Set(df, 1.0f);
    if (!hn::AllFalse(df, geometry)) {
      // hbao_receiver; a tail lane repeats the row's last pixel at its own x (dropped).
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

      // pyramid_hbao_directions: the blue-noise rotation of each lane, as the scalar code.
      HWY_ALIGN float rotation_lanes[hn::MaxLanes(df)];
      for (int i = 0; i < lanes; ++i) {
        float rotation = 0.0f;
        if (s.rotation) {
          rotation = blue_noise_value(ranks, x0 + i + shift_x, y + shift_y) + global;
          if (rotation >= 1.0f) rotation -= 1.0f;
        }
        rotation_lanes[i] = rotation;
      }
      const VF rotation = hn::Load(df, rotation_lanes);
      VF occlusion = hn::Zero(df);
      for (int dir = 0; dir < s.directions; ++dir) {
        const VF place = s.random_directions
                             ? PixelRandom(df, seed, x0, y, 2u * std::uint32_t(dir))
                             : hn::Zero(df);
        const VF theta =
            hn::Mul(hn::Set(df, sector), hn::Add(hn::Add(hn::Set(df, float(dir)), rotation), place));
        const VF m =
            s.random_start
                ? hn::Add(hn::Set(df, kPyramidHbaoStartMin),
                          hn::Mul(hn::Set(df, kPyramidHbaoStartMax - kPyramidHbaoStartMin),
                                  PixelRandom(df, seed, x0, y, 2u * std::uint32_t(dir) + 1u)))
                : hn::Set(df, 1.0f);
        const VF c = hn::Cos(df, theta), sn = hn::Sin(df, theta);
        occlusion = hn::Add(occlusion,
                            float_index ? MarchDirection<true>(df, f, s, p, k, geometry, c, sn, m)
                                        : MarchDirection<false>(df, f, s, p, k, geometry, c, sn, m));
      }
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

// Tiles of 16 rows × 128 columns, as HBAO's: the reads of a tile (a few pixels around it on
// level 0, a few texels on the coarser levels) stay in the core's L1 and L2.
constexpr int kPyramidHbaoBandRows = 16;
constexpr int kPyramidHbaoTileColumns = 128;

Image pyramid_hbao_simd(const GatherPyramid& pyramid, const float* normals,
                        const CameraIntrinsics& cam, const PyramidHbaoSettings& s, int threads,
                        Progress* progress) {
  const GatherPyramidLevel& base = pyramid.level(0);
  const pyramid_simd::Frame frame{pyramid.data(), pyramid.levels(), normals, base.width,
                                  base.height, cam};
  return image_from_tiles(
      base.width, base.height, threads, progress, kPyramidHbaoBandRows, kPyramidHbaoTileColumns,
      [] { return 0; },
      [&](int, int y, int x0, int x1, float* out) {
        HWY_DYNAMIC_DISPATCH(PyramidHbaoSpan)(frame, s, y, x0, x1, out);
      });
}

}  // namespace aolab
#endif  // HWY_ONCE
