// The SIMD form of the slice set-up in slice.h, shared by the SIMD kernels of GTAO
// (gtao_simd.cpp) and the visibility bitmask (bitmask_simd.cpp): lanes are consecutive pixels
// of one row, and each lane follows the scalar pixel's steps (its rotation, jitter, snapped
// texels, tangent tests), so the kernels differ from the scalar code by float rounding only.
//
// The algebra the scalar code leaves on the table (docs/methods/gtao.md, "SIMD kernel"):
// - the slice angle n = atan2(proj n · t, proj n · v) is needed for the linear term of eq. 7
//   only; cos n and sin n are the two dot products over their length, not cos and sin of n;
// - the per-pixel rotation is one sin/cos per pixel turning the base direction table
//   (HorizonDirections), as in the scalar code, but for a vector of pixels at once;
// - P's step in pixels is the same for every slice up to the direction: R/(d·M) once per
//   pixel;
// - a sample's distance from the slice plane's normal line, |D − a(a·D)|, and its cosine from
//   v take one reciprocal square root (hardware estimate and a Newton step);
// - the per-sample tangent test first runs HBAO's division-free prefilter.
//
// Included once per target by a kernel's own foreach_target pass, hence Highway's per-target
// include guard instead of #pragma once.
#if defined(AOLAB_HORIZON_SLICE_SIMD_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef AOLAB_HORIZON_SLICE_SIMD_INL_H_
#undef AOLAB_HORIZON_SLICE_SIMD_INL_H_
#else
#define AOLAB_HORIZON_SLICE_SIMD_INL_H_
#endif

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>

#include "core/base/simd-inl.h"
#include "core/horizon/horizon_simd-inl.h"
#include "core/horizon/slice.h"

HWY_BEFORE_NAMESPACE();
namespace aolab::HWY_NAMESPACE {
namespace slice_simd {

/// What every vector of a row shares.
struct Row {
  VF inv_fx, inv_fy, fx, fy, width, height;
  int y, w;
  MipSampling<DF> mip;  // far samples on the depth MIP chain (HorizonFrame::mip)
};

inline Row make_row(DF df, const SliceFrame& f, int y) {
  Row k;
  k.inv_fx = hn::Set(df, 1.0f / f.cam.fx), k.inv_fy = hn::Set(df, 1.0f / f.cam.fy);
  k.fx = hn::Set(df, f.cam.fx), k.fy = hn::Set(df, f.cam.fy);
  k.width = hn::Set(df, float(f.width)), k.height = hn::Set(df, float(f.height));
  k.y = y, k.w = f.width;
  k.mip = MakeMipSampling(df, f);
  return k;
}

/// slice_pixel on every lane: the receiver (horizon_receiver), the view vector, the jitter and
/// the rotation of the direction table.
struct Pixels {
  MF geometry;  // not background
  VF d, nx, ny, nz, px, py, ox, oy;
  VI x;
  VF n_r0, grazing;  // n · r0, |r0| / |n·r0|
  VF vx, vy, vz;     // v = −P/|P|
  VF jitter;         // the samples' offset w
  VF rot_c, rot_s;   // cos and sin of the per-pixel rotation
  VF step_scale;     // R/(d·M): horizon_step without the direction
};

/// The pixels x0 … x0 + Lanes − 1 of row k.y (count of them real; the others repeat the last
/// real pixel's data at their own x and their results are dropped).
inline Pixels load_pixels(DF df, const SliceFrame& f, const Row& k, int x0, int count, int seed,
                          bool random_rotation, bool jitter, int directions, float radius,
                          int steps) {
  const DI di;
  Pixels p;
  const std::size_t row = std::size_t(k.y) * f.width;
  p.d = LoadRowPart(df, f.depth + row + x0, count);
  p.geometry = hn::Eq(p.d, p.d);  // background is NaN
  const float* normal_row = f.normals + 3 * row;
  if (count == int(hn::Lanes(df))) {
    hn::LoadInterleaved3(df, normal_row + 3 * std::size_t(x0), p.nx, p.ny, p.nz);
  } else {
    HWY_ALIGN float n[3][hn::MaxLanes(df)];
    for (int i = 0; i < int(hn::Lanes(df)); ++i)
      for (int c = 0; c < 3; ++c)
        n[c][i] = normal_row[3 * std::size_t(x0 + std::min(i, count - 1)) + c];
    p.nx = hn::Load(df, n[0]), p.ny = hn::Load(df, n[1]), p.nz = hn::Load(df, n[2]);
  }
  // Background lanes get a harmless depth, so that no NaN reaches a reciprocal estimate.
  p.d = hn::IfThenElse(p.geometry, p.d, hn::Set(df, 1.0f));
  const float py = float(k.y) + 0.5f;
  p.x = hn::Add(hn::Set(di, x0), hn::Iota(di, 0));
  p.px = PixelCentres(df, x0), p.py = hn::Set(df, py);
  p.ox = hn::Sub(p.px, hn::Set(df, f.cam.cx)), p.oy = hn::Set(df, py - f.cam.cy);
  const VF r0x = hn::Mul(p.ox, k.inv_fx), r0y = hn::Neg(hn::Mul(p.oy, k.inv_fy));
  p.n_r0 = hn::Sub(hn::MulAdd(p.nx, r0x, hn::Mul(p.ny, r0y)), p.nz);
  const VF r0_len2 = hn::MulAdd(r0x, r0x, hn::MulAdd(r0y, r0y, hn::Set(df, 1.0f)));
  p.grazing = hn::Div(hn::Sqrt(r0_len2), hn::Abs(p.n_r0));
  // v = normalize(−r0) (slice_view_vector).
  const VF inv_r0 = RecipSqrt(df, r0_len2);
  p.vx = hn::Neg(hn::Mul(r0x, inv_r0)), p.vy = hn::Neg(hn::Mul(r0y, inv_r0)), p.vz = inv_r0;
  const auto s = std::uint32_t(seed);
  const VF rotation = random_rotation ? PixelRandom(df, s, x0, k.y, 0) : hn::Zero(df);
  p.jitter = jitter ? PixelRandom(df, s, x0, k.y, 1) : hn::Zero(df);
  // HorizonDirections::rotated: the table of `directions` directions turned by a fraction
  // `rotation` of their spacing.
  const VF phi = hn::Mul(rotation, hn::Set(df, float(2.0 * std::numbers::pi / directions)));
  p.rot_c = hn::Cos(df, phi), p.rot_s = hn::Sin(df, phi);
  p.step_scale = hn::Div(hn::Set(df, radius), hn::Mul(p.d, hn::Set(df, float(steps))));
  return p;
}

/// make_slice_geometry on every lane, for the base direction (bc, bs) of the table.
struct Slice {
  MF active;           // a pixel with |proj n| > 0: the others skip the slice
  VF ax, ay, az;       // unit normal of the slice plane
  VF tx, ty, tz;       // in the plane, ⊥ v, towards side 0
  VF length;           // |proj n|, eq. 8's weight
  VF n, cos_n, sin_n;  // the angle from v to proj n, towards side 0
  VF low[2];           // tangent cosines of side 0 and side 1
  VF step_x, step_y;   // image step of side 0
};

inline Slice make_slice(DF df, const Row& k, const Pixels& p, float bc, float bs) {
  const VF zero = hn::Zero(df);
  Slice sl;
  // The rotated direction (c, s) (HorizonDirections::rotated).
  const VF c = hn::Sub(hn::Mul(hn::Set(df, bc), p.rot_c), hn::Mul(hn::Set(df, bs), p.rot_s));
  const VF s = hn::MulAdd(hn::Set(df, bs), p.rot_c, hn::Mul(hn::Set(df, bc), p.rot_s));
  // axis = normalize((c, s, 0) × v); v.z > 0, so the cross product is never zero.
  const VF cx = hn::Mul(s, p.vz), cy = hn::Neg(hn::Mul(c, p.vz));
  const VF cz = hn::Sub(hn::Mul(c, p.vy), hn::Mul(s, p.vx));
  const VF inv_c = RecipSqrt(df, hn::MulAdd(cx, cx, hn::MulAdd(cy, cy, hn::Mul(cz, cz))));
  sl.ax = hn::Mul(cx, inv_c), sl.ay = hn::Mul(cy, inv_c), sl.az = hn::Mul(cz, inv_c);
  // tangent = v × axis.
  sl.tx = hn::Sub(hn::Mul(p.vy, sl.az), hn::Mul(p.vz, sl.ay));
  sl.ty = hn::Sub(hn::Mul(p.vz, sl.ax), hn::Mul(p.vx, sl.az));
  sl.tz = hn::Sub(hn::Mul(p.vx, sl.ay), hn::Mul(p.vy, sl.ax));
  // proj n = n − axis (n · axis).
  const VF n_a = hn::MulAdd(p.nx, sl.ax, hn::MulAdd(p.ny, sl.ay, hn::Mul(p.nz, sl.az)));
  const VF qx = hn::NegMulAdd(sl.ax, n_a, p.nx), qy = hn::NegMulAdd(sl.ay, n_a, p.ny);
  const VF qz = hn::NegMulAdd(sl.az, n_a, p.nz);
  const VF len2 = hn::MulAdd(qx, qx, hn::MulAdd(qy, qy, hn::Mul(qz, qz)));
  sl.active = hn::And(p.geometry, hn::Gt(len2, zero));
  const VF safe_len2 = hn::IfThenElse(sl.active, len2, hn::Set(df, 1.0f));
  const VF inv_len = RecipSqrt(df, safe_len2);
  sl.length = hn::IfThenElseZero(sl.active, hn::Mul(safe_len2, inv_len));
  const VF along_v = hn::Max(zero, hn::MulAdd(qx, p.vx, hn::MulAdd(qy, p.vy, hn::Mul(qz, p.vz))));
  const VF along_t = hn::MulAdd(qx, sl.tx, hn::MulAdd(qy, sl.ty, hn::Mul(qz, sl.tz)));
  // cos n, sin n of n = atan2(along_t, along_v) without trigonometry; the scalar code's
  // tangent cosines divide along_t by |proj n| (equal to the hypotenuse unless along_v was
  // clamped, which only rounding makes happen).
  sl.n = QuadrantAtan2(df, along_t, along_v);
  const VF h2 = hn::MulAdd(along_v, along_v, hn::Mul(along_t, along_t));
  const MF has_h = hn::Gt(h2, zero);
  const VF inv_h = RecipSqrt(df, hn::IfThenElse(has_h, h2, hn::Set(df, 1.0f)));
  sl.cos_n = hn::IfThenElse(has_h, hn::Mul(along_v, inv_h), hn::Set(df, 1.0f));
  sl.sin_n = hn::IfThenElseZero(has_h, hn::Mul(along_t, inv_h));
  const VF sin_low = hn::IfThenElseZero(sl.active, hn::Mul(along_t, inv_len));
  sl.low[0] = hn::Neg(sin_low), sl.low[1] = sin_low;
  // horizon_step.
  sl.step_x = hn::Mul(hn::Mul(c, k.fx), p.step_scale);
  sl.step_y = hn::Neg(hn::Mul(hn::Mul(s, k.fy), p.step_scale));
  return sl;
}

/// D = S − P of a sample on P's pixel + (qx, qy) at depth ds (slice_sample_offset).
struct Offset {
  VF qx, qy, x, y, z, r2;
};

inline Offset sample_offset(DF df, const Row& k, const Pixels& p, VI sx, VI sy, VF ds) {
  const DI di;
  Offset o;
  o.qx = hn::ConvertTo(df, hn::Sub(sx, p.x));
  o.qy = hn::ConvertTo(df, hn::Sub(sy, hn::Set(di, k.y)));
  const VF dd = hn::Sub(ds, p.d);
  o.x = hn::Mul(hn::MulAdd(o.qx, ds, hn::Mul(p.ox, dd)), k.inv_fx);
  o.y = hn::Neg(hn::Mul(hn::MulAdd(o.qy, ds, hn::Mul(p.oy, dd)), k.inv_fy));
  o.z = hn::Neg(dd);
  o.r2 = hn::MulAdd(o.x, o.x, hn::MulAdd(o.y, o.y, hn::Mul(o.z, o.z)));
  return o;
}

/// above_tangent_plane on the lanes of `live` (false elsewhere). First HBAO's
/// division-free prefilter: where the sample's ray meets the plane in front of the camera
/// (n·rs < 0, n·r0 < 0), the test needs tau > ds·(1 + 16·2^-24), since its tolerance is at
/// least 2^-24·ds·(8 + 4·(1 + 1)); for n·rs < 0 that is d·(n·r0) < ds·(n·rs)·(1 + 16·2^-24).
/// The prefilter keeps 12 of the 16 ulps (the products' rounding takes the rest), so a lane
/// it drops fails the exact test anyway, and on open surfaces it drops every lane.
inline MF above_tangent_plane(DF df, const Row& k, const Pixels& p, MF live, VF qx, VF qy, VF ds) {
  const VF zero = hn::Zero(df);
  const VF rsx = hn::Mul(hn::Add(p.ox, qx), k.inv_fx);
  const VF rsy = hn::Neg(hn::Mul(hn::Add(p.oy, qy), k.inv_fy));
  const VF n_rs = hn::Sub(hn::MulAdd(p.nx, rsx, hn::Mul(p.ny, rsy)), p.nz);
  const MF meets = hn::And(hn::Lt(n_rs, zero), hn::Lt(p.n_r0, zero));
  const VF margin = hn::Set(df, 1.0f + 12.0f * kUnitRoundoff);
  const MF maybe = hn::And(
      live,
      hn::Or(hn::Not(meets), hn::Lt(hn::Mul(p.d, p.n_r0), hn::Mul(hn::Mul(ds, n_rs), margin))));
  if (hn::AllFalse(df, maybe)) return maybe;
  return ExactTangentTest(df, hn::Mul(p.d, p.n_r0), n_rs, rsx, rsy, ds, p.grazing, maybe).counts;
}

/// The texels and depths of steps i0 … i0 + n − 1 of one side (side 0: +step, side 1: −step)
/// into the chunk arrays (Lanes values per step), on the lanes of `alive`, which loses the
/// lanes whose march leaves the image (the scalar loop's break: final). Returns the steps
/// gathered (fewer than n once every lane has left). `live` holds the lanes for which the
/// scalar code would call its visitor: in the image, not P's texel, not background.
HWY_INLINE int gather_steps(DF df, const SliceFrame& f, const Row& k, const Pixels& p, VF step_x,
                            VF step_y, int i0, int n, MF& alive, std::int32_t* HWY_RESTRICT sxs,
                            std::int32_t* HWY_RESTRICT sys, float* HWY_RESTRICT dss,
                            float* HWY_RESTRICT live) {
  const DI di;
  const VF zero = hn::Zero(df);
  const VI row = hn::Set(di, k.y);
  const std::size_t lanes = hn::Lanes(df);
  // |step| in pixels, for the MIP level (as march_slice_side: no fused add).
  const VF step_len = hn::Sqrt(hn::Add(hn::Mul(step_x, step_x), hn::Mul(step_y, step_y)));
  for (int j = 0; j < n; ++j) {
    const VF t = hn::Sub(hn::Set(df, float(i0 + j)), p.jitter);
    const VF sx_f = hn::MulAdd(t, step_x, p.px), sy_f = hn::MulAdd(t, step_y, p.py);
    // Leaving the image is final for a lane; NaN fails too.
    alive = hn::And(alive, hn::And(hn::And(hn::Ge(sx_f, zero), hn::Lt(sx_f, k.width)),
                                   hn::And(hn::Ge(sy_f, zero), hn::Lt(sy_f, k.height))));
    if (hn::AllFalse(df, alive)) return j;
    VI sx = hn::ConvertTo(di, hn::IfThenElseZero(alive, sx_f));  // snap to the texel
    VI sy = hn::ConvertTo(di, hn::IfThenElseZero(alive, sy_f));
    const VI index = k.mip.on ? MipSampleIndex(df, k.mip, hn::Mul(t, step_len), sx, sy)
                              : hn::Add(hn::Mul(sy, hn::Set(di, k.w)), sx);
    const MF self = hn::RebindMask(df, hn::And(hn::Eq(sx, p.x), hn::Eq(sy, row)));
    const VF ds = hn::GatherIndex(df, f.depth, index);
    hn::Store(sx, di, sxs + j * lanes);
    hn::Store(sy, di, sys + j * lanes);
    hn::Store(ds, df, dss + j * lanes);
    // Background texels (NaN) are skipped.
    hn::Store(hn::VecFromMask(df, hn::And(hn::AndNot(self, alive), hn::Eq(ds, ds))), df,
              live + j * lanes);
  }
  return n;
}

/// march_slice_side on both sides of a slice, on every lane of sl.active: the texels and
/// depths of up to 16 steps of each side are gathered before any sample is visited, so that
/// the gathers' latencies overlap (the visits' data-dependent branches would otherwise stall
/// each gather behind a mispredicted one). visit(side, visited, sx, sy, ds) runs for every
/// step of side 0 in order, then for every step of side 1 in order (what the scalar code
/// does), `visited` the lanes for which the scalar code calls its visitor.
template <class Visit>
HWY_INLINE void march_sides(DF df, const SliceFrame& f, const Row& k, const Pixels& p,
                            const Slice& sl, int steps, Visit&& visit) {
  const DI di;
  constexpr int kChunk = 16;
  const std::size_t lanes = hn::Lanes(df);
  HWY_ALIGN std::int32_t sxs[2][kChunk * hn::MaxLanes(di)];
  HWY_ALIGN std::int32_t sys[2][kChunk * hn::MaxLanes(di)];
  HWY_ALIGN float dss[2][kChunk * hn::MaxLanes(df)];
  HWY_ALIGN float live[2][kChunk * hn::MaxLanes(df)];
  const VF step_x[2] = {sl.step_x, hn::Neg(sl.step_x)};
  const VF step_y[2] = {sl.step_y, hn::Neg(sl.step_y)};
  MF alive[2] = {sl.active, sl.active};
  const auto visit_chunk = [&](int side, int marched) {
    for (int j = 0; j < marched; ++j) {
      const MF visited = hn::MaskFromVec(hn::Load(df, live[side] + j * lanes));
      if (hn::AllFalse(df, visited)) continue;
      visit(side, visited, hn::Load(di, sxs[side] + j * lanes), hn::Load(di, sys[side] + j * lanes),
            hn::Load(df, dss[side] + j * lanes));
    }
  };
  if (steps <= kChunk) {
    const int marched0 = gather_steps(df, f, k, p, step_x[0], step_y[0], 1, steps, alive[0], sxs[0],
                                      sys[0], dss[0], live[0]);
    const int marched1 = gather_steps(df, f, k, p, step_x[1], step_y[1], 1, steps, alive[1], sxs[1],
                                      sys[1], dss[1], live[1]);
    visit_chunk(0, marched0);
    visit_chunk(1, marched1);
    return;
  }
  for (int side = 0; side < 2; ++side)
    for (int i0 = 1; i0 <= steps; i0 += kChunk) {
      const int n = std::min(kChunk, steps - i0 + 1);
      const int marched = gather_steps(df, f, k, p, step_x[side], step_y[side], i0, n, alive[side],
                                       sxs[side], sys[side], dss[side], live[side]);
      visit_chunk(side, marched);
      if (marched < n) break;
    }
}

}  // namespace slice_simd
}  // namespace aolab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // AOLAB_HORIZON_SLICE_SIMD_INL_H_
