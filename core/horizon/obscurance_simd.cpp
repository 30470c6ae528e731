// The SIMD kernel of the obscurance estimator that Alchemy AO and SAO share
// (obscurance_simd.h): obscurance_estimate of obscurance_estimator.h, the oracle it is tested
// against, on Lanes consecutive pixels of a row at once, compiled by Highway for every target
// and dispatched at run time. Every setting of both methods is supported; each lane follows the
// scalar pixel's steps (its own rotation, the same taps, texels, pyramid levels and tests).
//
// What it does differently (docs/methods/alchemy.md, "SIMD kernel"):
// - float instead of double, with v measured in units of r (v/r): the estimator becomes
//   (c·σ/s) Σ w·max(0, v'·n − b/r)/(v'·v' + ε) with v' = v/r, whose numbers stay near 1 for
//   every r in [1e-12, 1e30] (the scalar code needs double because r² reaches 1e60);
// - the per-pixel rotation's cos and sin from Highway (a few ulps from the C library's), and
//   multiplies and adds fused;
// - the taps' depths gathered for up to 16 taps before any of them is tested, so that the
//   gathers' latencies overlap; the tangent-plane test (with its division) runs only when
//   some lane's tap passed the cheap tests, and its grazing factors, which only scale its
//   tolerance, come from the hardware's reciprocal and 1/sqrt estimates.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/horizon/obscurance_simd.cpp"

#include "core/horizon/obscurance_simd.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>

#include "core/base/parallel.h"
#include "core/base/simd-inl.h"
#include "core/base/simd_tiles.h"
#include "core/horizon/receiver.h"

HWY_BEFORE_NAMESPACE();
namespace aolab::HWY_NAMESPACE {
namespace {

constexpr int kChunk = 16;  // taps gathered before they are tested

// The receiver C of each lane (horizon_receiver) and what its taps share.
struct Receiver {
  VF d, nx, ny, nz;
  VF px, py, ox, oy;
  VI x;
  VF n_r0, grazing;  // n·r0 and |r0|/|n·r0| (above_tangent_plane)
  VF bias;           // b/r
};

// The pyramid level of a tap at distance h (pixels), SAO §2.3: clamp(⌊log2 h⌋ − q', 0,
// L_max) for h ≥ 1, else 0. ⌊log2 h⌋ is the exponent field of h ≥ 1 (inf gives 128 and is
// clamped, NaN fails h ≥ 1), so this is the scalar code's ilogb exactly.
HWY_INLINE VI TapLevel(DF df, VF h, int q, int max_level) {
  const DI di;
  const VI exponent = hn::Sub(hn::ShiftRight<23>(hn::BitCast(di, h)), hn::Set(di, 127 + q));
  const VI level = hn::Min(hn::Max(exponent, hn::Zero(di)), hn::Set(di, max_level));
  return hn::IfThenElseZero(hn::RebindMask(di, hn::Ge(h, hn::Set(df, 1.0f))), level);
}

// base[index] on every lane.
template <class D>
HWY_INLINE hn::Vec<D> Gather(D d, const hn::TFromD<D>* HWY_RESTRICT base, VI index) {
  return hn::GatherIndex(d, base, index);
}

// What every pixel of a row reads: the frame, its constants in vectors.
struct RowConstants {
  int w, h;
  const float* depth_row;
  const float* normal_row;
  float py;  // the row's pixel centre
  VI row;
  VF v_inv_fx, v_inv_fy, kx, ky, v_inv_r, width_f, height_f;
  VF epsilon, scale;  // ε in units of r², c·σ/s
  VF tol_ulps, normal_ulps;
  bool smooth;     // the smooth falloff (1 − v·v)³
  bool at_source;  // SAO's taps at their coarse texels' source pixels
  int max_level;
};

HWY_INLINE RowConstants MakeRowConstants(DF df, const ObscuranceSimdFrame& f, int y) {
  const DI di;
  const ObscuranceEstimator& e = *f.estimator;
  const ObscuranceLevels* lv = f.levels;
  RowConstants k;
  k.w = f.width, k.h = f.height;
  k.depth_row = f.depth + std::size_t(y) * k.w;
  k.normal_row = f.normals + 3 * std::size_t(y) * k.w;
  k.py = float(y) + 0.5f;
  k.row = hn::Set(di, y);
  const float inv_fx = 1.0f / f.cam.fx, inv_fy = 1.0f / f.cam.fy;
  const float inv_r = 1.0f / f.radius;
  k.v_inv_fx = hn::Set(df, inv_fx), k.v_inv_fy = hn::Set(df, inv_fy);
  k.kx = hn::Set(df, inv_fx * inv_r), k.ky = hn::Set(df, inv_fy * inv_r);
  k.v_inv_r = hn::Set(df, inv_r);
  k.width_f = hn::Set(df, float(k.w)), k.height_f = hn::Set(df, float(k.h));
  k.epsilon = hn::Set(df, float(e.epsilon * e.inv_r2));
  k.scale = hn::Set(df, float(e.scale / double(f.radius)));
  k.tol_ulps = hn::Set(df, kTangentDepthUlps), k.normal_ulps = hn::Set(df, kTangentNormalUlps);
  k.smooth = e.falloff == ObscuranceFalloff::Smooth;
  k.at_source = lv && lv->has_sources();
  k.max_level = lv ? lv->count - 1 : 0;
  return k;
}

// The receivers of pixels x0 … x0 + Lanes − 1 (count of them in the span; a tail lane repeats
// the span's last pixel's data at its own x, and its result is dropped). False when all are
// background.
HWY_INLINE bool LoadReceiver(DF df, const ObscuranceSimdFrame& f, const RowConstants& k, int x0,
                             int count, Receiver& p, MF& geometry) {
  const DI di;
  const VF one = hn::Set(df, 1.0f);
  const std::size_t lanes = hn::Lanes(df);
  p.d = LoadRowPart(df, k.depth_row + x0, count);
  geometry = hn::Eq(p.d, p.d);  // background is NaN
  if (hn::AllFalse(df, geometry)) return false;
  if (count == int(lanes)) {
    hn::LoadInterleaved3(df, k.normal_row + 3 * std::size_t(x0), p.nx, p.ny, p.nz);
  } else {
    HWY_ALIGN float n[3][hn::MaxLanes(df)];
    for (int i = 0; i < int(lanes); ++i)
      for (int c = 0; c < 3; ++c)
        n[c][i] = k.normal_row[3 * std::size_t(x0 + std::min(i, count - 1)) + c];
    p.nx = hn::Load(df, n[0]), p.ny = hn::Load(df, n[1]), p.nz = hn::Load(df, n[2]);
  }
  p.x = hn::Add(hn::Set(di, x0), hn::Iota(di, 0));
  p.px = PixelCentres(df, x0), p.py = hn::Set(df, k.py);
  p.ox = hn::Sub(p.px, hn::Set(df, f.cam.cx)), p.oy = hn::Set(df, k.py - f.cam.cy);
  const VF r0x = hn::Mul(p.ox, k.v_inv_fx), r0y = hn::Neg(hn::Mul(p.oy, k.v_inv_fy));
  p.n_r0 = hn::Sub(hn::MulAdd(p.nx, r0x, hn::Mul(p.ny, r0y)), p.nz);
  p.grazing = hn::ApproximateReciprocal(  // as grazing_s: it only scales a tolerance
      hn::Mul(hn::ApproximateReciprocalSqrt(hn::MulAdd(r0x, r0x, hn::MulAdd(r0y, r0y, one))),
              hn::Abs(p.n_r0)));
  p.bias = hn::MulAdd(hn::Set(df, f.bias_per_depth), p.d, hn::Set(df, f.bias_constant));
  return true;
}

// Every lane's disc of radius r at depth d: r·fx/d pixels across, r·fy/d down (as the scalar
// code rounds them), r_max for SAO's pyramid levels, and the rotation φ = 2π·pixel_random,
// one cos and sin per pixel.
struct Disc {
  VF rx, ry, r_max, cr, sr;
};

HWY_INLINE Disc MakeDisc(DF df, const ObscuranceSimdFrame& f, const Receiver& p, int x0, int y) {
  const VF one = hn::Set(df, 1.0f), zero = hn::Zero(df);
  Disc c;
  c.rx = hn::Div(hn::Set(df, f.radius * f.cam.fx), p.d);
  c.ry = hn::Div(hn::Set(df, f.radius * f.cam.fy), p.d);
  c.r_max = f.levels ? hn::Div(hn::Set(df, f.levels->r_max_scale), p.d) : zero;
  c.cr = one, c.sr = zero;
  if (f.random_rotation) {
    const VF phi = hn::Mul(hn::Set(df, 2.0f * std::numbers::pi_v<float>),
                           PixelRandom(df, std::uint32_t(f.seed), x0, y, 0));
    c.cr = hn::Cos(df, phi), c.sr = hn::Sin(df, phi);
  }
  return c;
}

// The pixel y·W + x a coarse texel was subsampled from (SaoTapPosition::Source): the row from
// a float quotient, off by at most one (|error| < 1 for y < 2^22, ObscuranceLevels), and
// corrected.
HWY_INLINE void SourcePixel(DF df, int w, VI src, VI& src_x, VI& src_y) {
  const DI di;
  src_y = hn::ConvertTo(di, hn::Mul(hn::ConvertTo(df, src), hn::Set(df, 1.0f / float(w))));
  src_x = hn::Sub(src, hn::Mul(src_y, hn::Set(di, w)));
  const MI low = hn::Lt(src_x, hn::Zero(di));
  src_y = hn::IfThenElse(low, hn::Sub(src_y, hn::Set(di, 1)), src_y);
  src_x = hn::IfThenElse(low, hn::Add(src_x, hn::Set(di, w)), src_x);
  const MI high = hn::Gt(src_x, hn::Set(di, w - 1));
  src_y = hn::IfThenElse(high, hn::Add(src_y, hn::Set(di, 1)), src_y);
  src_x = hn::IfThenElse(high, hn::Sub(src_x, hn::Set(di, w)), src_x);
}

// SAO's depth of a tap at texel (sx, sy) of level `level` (level 0, the full-resolution depth,
// where `coarse` is false); with sources, (sx, sy) become the coarse texels' source pixels.
HWY_INLINE VF PyramidDepth(DF df, const ObscuranceSimdFrame& f, const RowConstants& k, VI level,
                           MI coarse, VI full_index, VI& sx, VI& sy) {
  const DI di;
  const ObscuranceLevels& lv = *f.levels;
  // Level m is ⌈W/2^m⌉ × ⌈H/2^m⌉ (each level halves the last, rounding up).
  const VI round_up = hn::Sub(hn::operator<<(hn::Set(di, 1), level), hn::Set(di, 1));
  const VI lw = hn::operator>>(hn::Add(hn::Set(di, k.w), round_up), level);
  const VI lh = hn::operator>>(hn::Add(hn::Set(di, k.h), round_up), level);
  const int level0 = hn::GetLane(level);
  const VI off = hn::AllTrue(di, hn::Eq(level, hn::Set(di, level0)))
                     ? hn::Set(di, lv.offset[std::size_t(level0)])
                     : Gather(di, lv.offset.data(), level);
  const VI mx = hn::Min(hn::operator>>(sx, level), hn::Sub(lw, hn::Set(di, 1)));
  const VI my = hn::Min(hn::operator>>(sy, level), hn::Sub(lh, hn::Set(di, 1)));
  const VI t = hn::IfThenElseZero(coarse, hn::Add(off, hn::Add(hn::Mul(my, lw), mx)));
  const VI at = lv.stride == 2 ? hn::Add(t, t) : t;
  VF ds = hn::BitCast(df, Gather(di, lv.texels.data(), at));
  const bool all_coarse = hn::AllTrue(di, coarse);
  if (!all_coarse)
    ds = hn::IfThenElse(hn::RebindMask(df, coarse), ds, Gather(df, f.depth, full_index));
  if (k.at_source) {
    VI src_x, src_y;
    SourcePixel(df, k.w, Gather(di, lv.texels.data(), hn::Add(at, hn::Set(di, 1))), src_x, src_y);
    sx = hn::IfThenElse(coarse, src_x, sx);
    sy = hn::IfThenElse(coarse, src_y, sy);
  }
  return ds;
}

// Taps i0 … i0 + n − 1 gathered before they are tested: each tap's texel and depth on every
// lane, and whether it is a tap at all (on the image, not the pixel itself).
struct Chunk {
  HWY_ALIGN std::int32_t sx[kChunk * hn::MaxLanes(DI())];
  HWY_ALIGN std::int32_t sy[kChunk * hn::MaxLanes(DI())];
  HWY_ALIGN float ds[kChunk * hn::MaxLanes(DF())];
  HWY_ALIGN float live[kChunk * hn::MaxLanes(DF())];
};

// Phase 1: the texels and depths of taps i0 … i0 + n − 1 (independent of each other: the
// gathers overlap).
HWY_INLINE void PlaceTaps(DF df, const ObscuranceSimdFrame& f, const RowConstants& k,
                          const Receiver& p, const Disc& disc, MF geometry, int i0, int n,
                          Chunk& c) {
  const DI di;
  const VF zero = hn::Zero(df);
  const std::size_t lanes = hn::Lanes(df);
  const SpiralTaps& taps = *f.taps;
  const ObscuranceLevels* lv = f.levels;
  for (int j = 0; j < n; ++j) {
    const int i = i0 + j;
    float bc, bs;
    taps.direction(i, 1.0f, 0.0f, bc, bs);  // the unrotated cos and sin of θ_i
    const VF vbc = hn::Set(df, bc), vbs = hn::Set(df, bs);
    const VF cs = hn::Sub(hn::Mul(vbc, disc.cr), hn::Mul(vbs, disc.sr));
    const VF sn = hn::MulAdd(vbs, disc.cr, hn::Mul(vbc, disc.sr));
    const VF a = hn::Set(df, taps.alpha(i));
    const VF sx_f = hn::MulAdd(hn::Mul(a, cs), disc.rx, p.px);
    const VF sy_f = hn::NegMulAdd(hn::Mul(a, sn), disc.ry, p.py);  // image y points down
    // Off the image (NaN and inf fail too): no tap.
    const MF inside =
        hn::And(hn::And(geometry, hn::And(hn::Ge(sx_f, zero), hn::Lt(sx_f, k.width_f))),
                hn::And(hn::Ge(sy_f, zero), hn::Lt(sy_f, k.height_f)));
    VI sx = hn::ConvertTo(di, hn::IfThenElseZero(inside, sx_f));  // the texel
    VI sy = hn::ConvertTo(di, hn::IfThenElseZero(inside, sy_f));
    // Level 0 is the full-resolution depth.
    const VI full_index = hn::Add(hn::Mul(sy, hn::Set(di, k.w)), sx);
    const VI level =
        lv ? TapLevel(df, hn::Mul(a, disc.r_max), lv->log_max_offset, k.max_level) : hn::Zero(di);
    const MI coarse = hn::Gt(level, hn::Zero(di));
    const VF ds = hn::AllFalse(di, coarse)
                      ? Gather(df, f.depth, full_index)
                      : PyramidDepth(df, f, k, level, coarse, full_index, sx, sy);
    const MF self = hn::RebindMask(df, hn::And(hn::Eq(sx, p.x), hn::Eq(sy, k.row)));
    hn::Store(sx, di, c.sx + j * lanes);
    hn::Store(sy, di, c.sy + j * lanes);
    hn::Store(ds, df, c.ds + j * lanes);
    hn::Store(hn::VecFromMask(df, hn::AndNot(self, inside)), df, c.live + j * lanes);
  }
}

// above_tangent_plane on the lanes of `live` for a tap at pixel offset (qx, qy) and depth
// ds. |rs|/|n·rs| only scales the tolerance: the hardware estimates (12 bits or better) will
// do where the scalar code divides by a square root; |n·rs| = 0 gives inf there too.
HWY_INLINE MF AboveTangentPlane(DF df, const RowConstants& k, const Receiver& p, VF qx, VF qy,
                                VF ds, MF live) {
  const VF one = hn::Set(df, 1.0f), zero = hn::Zero(df);
  const VF rsx = hn::Mul(hn::Add(p.ox, qx), k.v_inv_fx);
  const VF rsy = hn::Neg(hn::Mul(hn::Add(p.oy, qy), k.v_inv_fy));
  const VF n_rs = hn::Sub(hn::MulAdd(p.nx, rsx, hn::Mul(p.ny, rsy)), p.nz);
  const VF tau = hn::Div(hn::Mul(p.d, p.n_r0), n_rs);
  const MF hits = hn::And(hn::And(hn::Lt(n_rs, zero), hn::Gt(tau, zero)), hn::IsFinite(tau));
  const MF rejected = hn::AndNot(hn::Gt(tau, ds), hits);
  const VF grazing_s = hn::ApproximateReciprocal(
      hn::Mul(hn::ApproximateReciprocalSqrt(hn::MulAdd(rsx, rsx, hn::MulAdd(rsy, rsy, one))),
              hn::Abs(n_rs)));
  const VF tol =
      hn::Mul(hn::Mul(hn::Set(df, kUnitRoundoff), hn::Max(ds, hn::IfThenElse(hits, tau, ds))),
              hn::MulAdd(k.normal_ulps, hn::Add(p.grazing, grazing_s), k.tol_ulps));
  const VF gap =
      hn::Sub(hn::IfThenElse(hits, tau, hn::Set(df, std::numeric_limits<float>::infinity())), ds);
  return hn::And(hn::AndNot(rejected, live), hn::Gt(gap, tol));
}

// Phase 2: the chunk's taps' terms (obscurance_tap) added to `sum`: w·(v·n − b)/(v·v + ε), all
// in units of r, where the tap is within r, above the bias and above the tangent plane.
HWY_INLINE void SumTaps(DF df, const RowConstants& k, const Receiver& p, int n, const Chunk& c,
                        VF& sum) {
  const DI di;
  const VF one = hn::Set(df, 1.0f);
  const std::size_t lanes = hn::Lanes(df);
  for (int j = 0; j < n; ++j) {
    const VI sx = hn::Load(di, c.sx + j * lanes), sy = hn::Load(di, c.sy + j * lanes);
    const VF ds = hn::Load(df, c.ds + j * lanes);
    const VF qx = hn::ConvertTo(df, hn::Sub(sx, p.x));
    const VF qy = hn::ConvertTo(df, hn::Sub(sy, k.row));
    const VF dd = hn::Sub(ds, p.d);
    // v/r, formed without cancellation as the scalar v.
    const VF vx = hn::Mul(hn::MulAdd(qx, ds, hn::Mul(p.ox, dd)), k.kx);
    const VF vy = hn::Neg(hn::Mul(hn::MulAdd(qy, ds, hn::Mul(p.oy, dd)), k.ky));
    const VF vz = hn::Neg(hn::Mul(dd, k.v_inv_r));
    const VF vv = hn::MulAdd(vx, vx, hn::MulAdd(vy, vy, hn::Mul(vz, vz)));
    const VF vn = hn::MulAdd(vx, p.nx, hn::MulAdd(vy, p.ny, hn::Mul(vz, p.nz)));
    // Within r (NaN, the background, fails) and v·n above the bias.
    MF live = hn::MaskFromVec(hn::Load(df, c.live + j * lanes));
    live = hn::And(live, hn::And(hn::Lt(vv, one), hn::Gt(vn, p.bias)));
    if (hn::AllFalse(df, live)) continue;
    live = AboveTangentPlane(df, k, p, qx, qy, ds, live);
    VF term = hn::Div(hn::Sub(vn, p.bias), hn::Add(vv, k.epsilon));
    if (k.smooth) {
      const VF fall = hn::Sub(one, vv);
      term = hn::Mul(term, hn::Mul(fall, hn::Mul(fall, fall)));
    }
    sum = hn::Add(sum, hn::IfThenElseZero(live, term));
  }
}

// ObscuranceEstimator::visibility: max(0, 1 − (c·σ/s)·Σ)^k in [0, 1], 1 with no tap (and on
// background).
HWY_INLINE VF Visibility(DF df, const ObscuranceEstimator& e, const RowConstants& k, VF sum,
                         MF geometry) {
  const VF one = hn::Set(df, 1.0f), zero = hn::Zero(df);
  VF a = hn::Max(zero, hn::NegMulAdd(k.scale, sum, one));
  if (e.contrast != 1.0) {
    const MF positive = hn::Gt(a, zero);
    a = hn::IfThenElseZero(positive,
                           hn::Exp(df, hn::Mul(hn::Set(df, float(e.contrast)),
                                               hn::Log(df, hn::IfThenElse(positive, a, one)))));
  }
  a = hn::Min(hn::Max(a, zero), one);
  return hn::IfThenElse(hn::And(geometry, hn::Gt(sum, zero)), a, one);
}

}  // namespace

// Pixels [x_begin, x_end) of row y into out (the row).
void ObscuranceSpan(const ObscuranceSimdFrame& f, int y, int x_begin, int x_end,
                    float* HWY_RESTRICT out) {
  const DF df;
  const RowConstants k = MakeRowConstants(df, f, y);
  const int count_taps = f.taps->size();
  Chunk c;
  ForEachSpanVector(df, x_begin, x_end, [&](int x0, int count) {
    Receiver p;
    MF geometry;
    if (!LoadReceiver(df, f, k, x0, count, p, geometry)) {
      StoreRowPart(df, hn::Set(df, 1.0f), count, out + x0);
      return;
    }
    const Disc disc = MakeDisc(df, f, p, x0, y);
    VF sum = hn::Zero(df);
    for (int i0 = 0; i0 < count_taps; i0 += kChunk) {
      const int n = std::min(kChunk, count_taps - i0);
      PlaceTaps(df, f, k, p, disc, geometry, i0, n, c);
      SumTaps(df, k, p, n, c, sum);
    }
    StoreRowPart(df, Visibility(df, *f.estimator, k, sum, geometry), count, out + x0);
  });
}

}  // namespace aolab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace aolab {

HWY_EXPORT(ObscuranceSpan);

Image obscurance_simd(const ObscuranceSimdFrame& f, int threads, Progress* progress) {
  return image_from_simd_tiles(f.width, f.height, threads, progress,
                               [&](int y, int x0, int x1, float* out) {
                                 HWY_DYNAMIC_DISPATCH(ObscuranceSpan)(f, y, x0, x1, out);
                               });
}

}  // namespace aolab
#endif  // HWY_ONCE
