// HBAO's SIMD kernel: the scalar per-pixel code of hbao.cpp (the oracle it is tested
// against) on Lanes consecutive pixels of a row at once, compiled by Highway for every target
// and dispatched at run time. Every setting is supported; each lane follows exactly the
// scalar pixel's steps (its own rotation, jitter, snapped texels, tangent tests), so the two
// differ only by float rounding (FMA, Highway's sin/cos for the rotation).
//
// What it does differently (docs/methods/hbao.md, "SIMD kernel"):
// - the depth of a sample is a gather, made for 32 step-vectors (4 directions at N_s = 8)
//   before any of them is tested, so that the gathers' latencies overlap; a lane whose march
//   left the image stops, as the scalar loop's break does, and the direction ends when every
//   lane has;
// - the per-sample tangent test first runs a division-free form of its sign test
//   ("is the sample nearer than the tangent plane on its ray, by more than the least
//   tolerance?"), before even D = S − P is built, and the radius test and the exact test
//   with its rounding tolerance, the square roots and divisions run only when a lane passes
//   it — on open surfaces no lane does; n·rs, affine in the texel offset, is two FMAs;
// - 1/sqrt by the hardware estimate and a Newton step where the scalar code divides by a
//   square root.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/methods/hbao/hbao_simd.cpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <vector>

#include "core/base/parallel.h"
#include "core/base/simd-inl.h"
#include "core/base/simd_tiles.h"
#include "core/horizon/horizon_simd-inl.h"
#include "core/methods/hbao/hbao.h"
#include "core/methods/hbao/hbao_shared.h"

HWY_BEFORE_NAMESPACE();
namespace aolab::HWY_NAMESPACE {
namespace {

// The receiver P of each lane (horizon_receiver).
struct Receiver {
  VF d, nx, ny, nz;
  VF px, py, ox, oy;
  VI x;        // P's column
  VF n_r0;     // n · (P's view ray at depth 1)
  VF grazing;  // |r0| / |n·r0|
  // n · rs of the view ray rs through P's pixel centre + (qx, qy) is affine in (qx, qy):
  // n_r0 + ax·qx − ay·qy with ax = nx/fx, ay = ny/fy, two operations per sample instead of
  // rebuilding rs (it differs from the scalar dot product by rounding only).
  VF ax, ay;
  VF d_n_r0;      // d · (n·r0)
  VF prefilter;   // d · (n·r0) / (1 + 12·2^-24), the prefilter's left side
  VF step_scale;  // horizon_step's R / (d·N_s)
};

// What every step of a row shares.
struct RowConstants {
  VF inv_fx, inv_fy, fx, fy, width, height, radius, radius2, inv_radius;
  int y, w;
  bool small;           // width and height < 2^23: TexelOf may be used
  MipSampling<DF> mip;  // far samples on the depth MIP chain (HorizonFrame::mip)
};

// int(v) for 0 ≤ v < 2^23: v + 2^23 holds trunc(v) in its low mantissa bits. Three
// operations where ConvertTo, which also handles out-of-range values, takes five.
HWY_INLINE VI TexelOf(DF df, VF v) {
  const DI di;
  const VF two23 = hn::Set(df, 8388608.0f);
  return hn::Sub(hn::BitCast(di, hn::Add(hn::Trunc(v), two23)), hn::BitCast(di, two23));
}

// elevation_sin_on_ray: sine of the elevation, seen from P, of the point at depth z on the
// view ray through P's pixel centre + (qx, qy).
HWY_INLINE VF ElevationSinOnRay(DF df, const Receiver& p, const RowConstants& k, VF qx, VF qy,
                                VF z) {
  const VF dz = hn::Sub(z, p.d);
  const VF dx = hn::Mul(hn::MulAdd(qx, z, hn::Mul(p.ox, dz)), k.inv_fx);
  const VF dy = hn::Neg(hn::Mul(hn::MulAdd(qy, z, hn::Mul(p.oy, dz)), k.inv_fy));
  const VF len2 = hn::MulAdd(dx, dx, hn::MulAdd(dy, dy, hn::Mul(dz, dz)));
  const MF positive = hn::Gt(len2, hn::Zero(df));
  const VF inv_len = RecipSqrt(df, hn::IfThenElse(positive, len2, hn::Set(df, 1.0f)));
  return hn::IfThenElseZero(positive, hn::Mul(hn::Neg(dz), inv_len));
}

// tangent_sin_in_azimuth: the tangent plane's elevation in the azimuth (ux, uy).
HWY_INLINE VF TangentSinInAzimuth(DF df, const Receiver& p, VF ux, VF uy) {
  const VF along = hn::MulAdd(p.nx, ux, hn::Mul(p.ny, uy));
  const VF denom = hn::Sqrt(
      hn::MulAdd(along, along, hn::Mul(hn::Mul(p.nz, p.nz), hn::MulAdd(ux, ux, hn::Mul(uy, uy)))));
  const VF signed_along = hn::IfThenElse(hn::Lt(p.nz, hn::Zero(df)), along, hn::Neg(along));
  return hn::IfThenElseZero(hn::Gt(denom, hn::Zero(df)), hn::Div(signed_along, denom));
}

// hbao_cosine_band on every lane.
HWY_INLINE VF CosineBand(DF df, VF a, VF nz, VF sin_a, VF cos_a, VF sin_t, VF cos_t) {
  const VF diff = QuadrantAtan2(df, hn::Sub(hn::Mul(sin_a, cos_t), hn::Mul(cos_a, sin_t)),
                                hn::MulAdd(cos_a, cos_t, hn::Mul(sin_a, sin_t)));
  const VF band = hn::Add(diff, hn::Sub(hn::Mul(sin_a, cos_a), hn::Mul(sin_t, cos_t)));
  return hn::MulAdd(a, band, hn::Mul(nz, hn::Sub(hn::Mul(sin_a, sin_a), hn::Mul(sin_t, sin_t))));
}

// direction_tangent_sin: the paper's one t(θ) per direction (per_sample_tangent off).
HWY_INLINE VF DirectionTangentSin(DF df, const Receiver& p, const RowConstants& k, VF step_x,
                                  VF step_y, VF c, VF s) {
  const VF len = hn::Sqrt(hn::MulAdd(step_x, step_x, hn::Mul(step_y, step_y)));
  const VF qx = hn::Div(step_x, len), qy = hn::Div(step_y, len);
  // tangent_on_ray for the ray through P's pixel centre + (qx, qy).
  const VF rx = hn::Mul(hn::Add(p.ox, qx), k.inv_fx);
  const VF ry = hn::Neg(hn::Mul(hn::Add(p.oy, qy), k.inv_fy));
  const VF n_r = hn::Sub(hn::MulAdd(p.nx, rx, hn::Mul(p.ny, ry)), p.nz);
  const VF tau = hn::Div(hn::Mul(p.d, p.n_r0), n_r);
  const MF hits =
      hn::And(hn::And(hn::Lt(n_r, hn::Zero(df)), hn::Gt(tau, hn::Zero(df))), hn::IsFinite(tau));
  // Outside `hits` tau may be anything: the elevation there is not used.
  const VF on_ray = ElevationSinOnRay(df, p, k, qx, qy, hn::IfThenElse(hits, tau, p.d));
  return hn::IfThenElse(hits, on_ray, TangentSinInAzimuth(df, p, c, s));
}

// The state of one direction's march on every lane.
struct March {
  VF best_gain, best_r, rises;
};

// One sample step of march_direction on every lane still marching (`live`): the candidate
// test of sample_candidate and the horizon update.
HWY_INLINE void SampleStep(DF df, const HbaoSettings& s, const Receiver& p, const RowConstants& k,
                           VF sin_t_dir, VF c, VF sn, MF live, VI sx, VI sy, VF ds, March& m) {
  const DI di;
  const VF zero = hn::Zero(df);
  const VF qx = hn::ConvertTo(df, hn::Sub(sx, p.x));
  const VF qy = hn::ConvertTo(df, hn::Sub(sy, hn::Set(di, k.y)));
  // With per-sample tangents the prefilter comes first: on an open surface it drops every
  // lane, and D and |D| need not be built.
  VF n_rs = zero;
  if (s.per_sample_tangent) {
    n_rs = hn::MulAdd(p.ax, qx, hn::NegMulAdd(p.ay, qy, p.n_r0));
    // The test without its division: where the ray meets the plane in front of the camera
    // (n·rs < 0 and n·r0 < 0, d > 0), tau − ds > tol needs tau > ds·(1 + 16·2^-24), since
    // tol ≥ 2^-24·ds·(8 + 4·(1 + 1)) (each g ≥ 1), and for n·rs < 0 that is
    // d·(n·r0) < ds·(n·rs)·(1 + 16·2^-24). A prefilter with 12 of the 16 ulps, divided into
    // d·(n·r0) once per pixel (that division's and the product's rounding take the rest): a
    // lane it drops fails the exact test below anyway, and on an open surface, where tau and
    // ds agree to a few ulps, it drops every lane.
    const MF meets = hn::And(hn::Lt(n_rs, zero), hn::Lt(p.n_r0, zero));
    live = hn::And(live, hn::Or(hn::Not(meets), hn::Lt(p.prefilter, hn::Mul(ds, n_rs))));
    if (hn::AllFalse(df, live)) return;
  }
  // D = S − P without cancellation (elevation_sin_on_ray).
  const VF dd = hn::Sub(ds, p.d);
  const VF dx = hn::Mul(hn::MulAdd(qx, ds, hn::Mul(p.ox, dd)), k.inv_fx);
  const VF dy = hn::Neg(hn::Mul(hn::MulAdd(qy, ds, hn::Mul(p.oy, dd)), k.inv_fy));
  const VF r2 = hn::MulAdd(dx, dx, hn::MulAdd(dy, dy, hn::Mul(dd, dd)));
  // Within R (NaN, the background, fails) and not P itself.
  live = hn::And(live, hn::And(hn::Le(r2, k.radius2), hn::Ne(r2, zero)));
  if (hn::AllFalse(df, live)) return;

  MF counts;
  VF gain, r;
  if (s.per_sample_tangent) {
    // per_sample_candidate, exactly.
    const VF rsx = hn::Mul(hn::Add(p.ox, qx), k.inv_fx);
    const VF rsy = hn::Neg(hn::Mul(hn::Add(p.oy, qy), k.inv_fy));
    const TangentTest<DF> t = ExactTangentTest(df, p.d_n_r0, n_rs, rsx, rsy, ds, p.grazing, live);
    const MF hits = t.hits;
    const VF tau = t.tau, inv_rs_len = t.inv_rs_len;
    counts = t.counts;
    if (hn::AllFalse(df, counts)) return;
    const VF sin_t =
        hn::IfThenElse(hits, ElevationSinOnRay(df, p, k, qx, qy, hn::IfThenElse(hits, tau, p.d)),
                       hn::Neg(inv_rs_len));
    const VF inv_r = RecipSqrt(df, r2);  // r2 > 0 on the counted lanes
    r = hn::Mul(r2, inv_r);
    gain = hn::MulSub(hn::Neg(dd), inv_r, sin_t);
  } else {
    r = hn::Sqrt(r2);
    gain = hn::Sub(hn::Div(hn::Neg(dd), r), sin_t_dir);
    const VF tol = hn::Add(
        hn::Set(df, kHbaoNormalTolerance),
        hn::Div(hn::Mul(hn::Set(df, kTangentDepthUlps * kUnitRoundoff), hn::Max(p.d, ds)), r));
    counts = hn::And(live, hn::Gt(gain, tol));
    if (hn::AllFalse(df, counts)) return;
  }

  if (s.integral == int(HbaoIntegral::Cosine)) {  // cosine_gain
    const VF sin_a = hn::Div(hn::Neg(dd), r);
    const VF hor = hn::Sqrt(hn::MulAdd(dx, dx, hn::Mul(dy, dy)));
    const VF cos_a = hn::Div(hor, r);
    if (!s.per_sample_tangent) {
      const VF a = hn::MulAdd(p.nx, c, hn::Mul(p.ny, sn));
      const VF cos_t =
          hn::Sqrt(hn::Max(zero, hn::NegMulAdd(sin_t_dir, sin_t_dir, hn::Set(df, 1.0f))));
      gain = CosineBand(df, a, p.nz, sin_a, cos_a, sin_t_dir, cos_t);
    } else {
      const MF has_hor = hn::Gt(hor, zero);
      const VF ux = hn::IfThenElse(has_hor, hn::Div(dx, hor), c);
      const VF uy = hn::IfThenElse(has_hor, hn::Div(dy, hor), sn);
      const VF a = hn::MulAdd(p.nx, ux, hn::Mul(p.ny, uy));
      const VF rho = hn::Sqrt(hn::MulAdd(a, a, hn::Mul(p.nz, p.nz)));
      const MF has_rho = hn::Gt(rho, zero);  // else n ⟂ the whole slice: n·ω = 0 in it
      const VF sin_t = hn::Div(hn::IfThenElse(hn::Lt(p.nz, zero), a, hn::Neg(a)), rho);
      const VF cos_t = hn::Div(hn::Abs(p.nz), rho);
      gain = hn::IfThenElseZero(has_rho, CosineBand(df, a, p.nz, sin_a, cos_a, sin_t, cos_t));
    }
  }

  // The horizon update of march_direction.
  const MF first = hn::Eq(m.best_r, zero);
  const MF rises_more = hn::Gt(gain, hn::Add(m.best_gain, hn::Set(df, kHbaoHorizonTie)));
  const MF update = hn::And(hn::And(counts, hn::Gt(gain, zero)), hn::Or(first, rises_more));
  if (hn::AllFalse(df, update)) return;
  const VF w = hn::Max(zero, hn::NegMulAdd(r, k.inv_radius, hn::Set(df, 1.0f)));
  m.rises = hn::IfThenElse(update, hn::MulAdd(hn::Sub(gain, m.best_gain), w, m.rises), m.rises);
  m.best_gain = hn::IfThenElse(update, gain, m.best_gain);
  m.best_r = hn::IfThenElse(update, r, m.best_r);
}

// What the march of one direction shares: its azimuth, step and (per_sample_tangent off) t(θ).
struct Direction {
  VF c, sn, step_x, step_y, sin_t_dir;
  VF step_len;  // |step| in pixels, for the MIP level (as the scalar code: no fused add)
};

HWY_INLINE Direction MakeDirection(DF df, const HbaoSettings& s, const Receiver& p,
                                   const RowConstants& k, VF c, VF sn) {
  Direction d;
  d.c = c, d.sn = sn;
  // horizon_step: the projected radius split into N_s steps.
  d.step_x = hn::Mul(hn::Mul(c, k.fx), p.step_scale);
  d.step_y = hn::Neg(hn::Mul(hn::Mul(sn, k.fy), p.step_scale));
  d.sin_t_dir = s.per_sample_tangent ? hn::Zero(df)
                                     : DirectionTangentSin(df, p, k, d.step_x, d.step_y, c, sn);
  d.step_len = hn::Sqrt(hn::Add(hn::Mul(d.step_x, d.step_x), hn::Mul(d.step_y, d.step_y)));
  return d;
}

// The step-vectors that one pass gathers before it tests any: enough gathers in flight to
// overlap their latency, few enough that the buffers (16 KiB at 16 lanes) stay in L1.
constexpr int kBufferSteps = 32;

// The texels and gathered depths of steps [i0, i0 + n) of direction d into the buffers at
// `at` step-vectors; `alive` (the lanes still in the image) is updated. Returns the steps
// marched: fewer than n when every lane has left the image.
struct StepBuffers {
  std::int32_t* sx;
  std::int32_t* sy;
  float* ds;
  float* live;
};
HWY_INLINE int GatherSteps(DF df, const HorizonFrame& f, const Receiver& p, const RowConstants& k,
                           const Direction& d, VF jitter, int i0, int n, MF& alive,
                           const StepBuffers& b, int at) {
  const DI di;
  const VF zero = hn::Zero(df);
  const VI row = hn::Set(di, k.y);
  const std::size_t lanes = hn::Lanes(df);
  for (int j = 0; j < n; ++j) {
    const VF t = hn::Sub(hn::Set(df, float(i0 + j)), jitter);
    const VF sx_f = hn::MulAdd(t, d.step_x, p.px), sy_f = hn::MulAdd(t, d.step_y, p.py);
    // Leaving the image is final for a lane (the scalar break); NaN fails too.
    alive = hn::And(alive, hn::And(hn::And(hn::Ge(sx_f, zero), hn::Lt(sx_f, k.width)),
                                   hn::And(hn::Ge(sy_f, zero), hn::Lt(sy_f, k.height))));
    if (hn::AllFalse(df, alive)) return j;
    // Snap to the texel (the same integers either way).
    const VF sx_in = hn::IfThenElseZero(alive, sx_f), sy_in = hn::IfThenElseZero(alive, sy_f);
    VI sx = k.small ? TexelOf(df, sx_in) : hn::ConvertTo(di, sx_in);
    VI sy = k.small ? TexelOf(df, sy_in) : hn::ConvertTo(di, sy_in);
    const VI index = k.mip.on ? MipSampleIndex(df, k.mip, hn::Mul(t, d.step_len), sx, sy)
                              : hn::Add(hn::Mul(sy, hn::Set(di, k.w)), sx);
    const MF self = hn::RebindMask(df, hn::And(hn::Eq(sx, p.x), hn::Eq(sy, row)));
    const std::size_t o = (at + j) * lanes;
    hn::Store(sx, di, b.sx + o);
    hn::Store(sy, di, b.sy + o);
    hn::Store(hn::GatherIndex(df, f.depth, index), df, b.ds + o);
    hn::Store(hn::VecFromMask(df, hn::AndNot(self, alive)), df, b.live + o);
  }
  return n;
}

// The tests of `count` buffered steps, from step-vector `at` on, into direction d's march m.
HWY_INLINE void TestSteps(DF df, const HbaoSettings& s, const Receiver& p, const RowConstants& k,
                          const Direction& d, const StepBuffers& b, int at, int count, March& m) {
  const DI di;
  const std::size_t lanes = hn::Lanes(df);
  for (int j = at; j < at + count; ++j) {
    const MF live = hn::MaskFromVec(hn::Load(df, b.live + j * lanes));
    SampleStep(df, s, p, k, d.sin_t_dir, d.c, d.sn, live, hn::Load(di, b.sx + j * lanes),
               hn::Load(di, b.sy + j * lanes), hn::Load(df, b.ds + j * lanes), m);
  }
}

// eq. 3's term of a direction from its finished march.
HWY_INLINE VF DirectionTerm(DF df, const HbaoSettings& s, const RowConstants& k, const March& m) {
  if (s.attenuation == int(HbaoAttenuation::None)) return m.best_gain;
  if (s.incremental_attenuation) return m.rises;
  return hn::Mul(m.best_gain,
                 hn::Max(hn::Zero(df), hn::NegMulAdd(m.best_r, k.inv_radius, hn::Set(df, 1.0f))));
}

// march_direction on every lane for every direction, summed in the scalar code's order
// (hbao_pixel). The march runs in passes: first every buffered sample's texel and gathered
// depth (independent of each other, so the gathers' memory latency overlaps), then the
// samples' tests, whose data-dependent branches would otherwise stall each gather behind a
// mispredicted one. When N_s ≤ kBufferSteps / 2 one pass holds several directions' steps
// (4 at N_s = 8), so that enough gathers are in flight; a longer march is cut into chunks.
HWY_INLINE VF MarchDirections(DF df, const HorizonFrame& f, const HbaoSettings& s,
                              const Receiver& p, const RowConstants& k, MF geometry, VF jitter,
                              VF cp, VF sp, const float* base_cos, const float* base_sin) {
  const DI di;
  HWY_ALIGN std::int32_t buf_sx[kBufferSteps * hn::MaxLanes(di)];
  HWY_ALIGN std::int32_t buf_sy[kBufferSteps * hn::MaxLanes(di)];
  HWY_ALIGN float buf_ds[kBufferSteps * hn::MaxLanes(df)];
  HWY_ALIGN float buf_live[kBufferSteps * hn::MaxLanes(df)];
  const StepBuffers b{buf_sx, buf_sy, buf_ds, buf_live};
  // HorizonDirections::rotated.
  const auto direction = [&](int dir) {
    const VF bc = hn::Set(df, base_cos[dir]), bs = hn::Set(df, base_sin[dir]);
    return MakeDirection(df, s, p, k, hn::Sub(hn::Mul(bc, cp), hn::Mul(bs, sp)),
                         hn::MulAdd(bs, cp, hn::Mul(bc, sp)));
  };
  VF occlusion = hn::Zero(df);
  constexpr int kMaxGroup = 8;
  const int group = std::clamp(kBufferSteps / s.steps, 1, kMaxGroup);
  if (group == 1) {
    for (int dir = 0; dir < s.directions; ++dir) {
      const Direction d = direction(dir);
      March m{hn::Zero(df), hn::Zero(df), hn::Zero(df)};
      MF alive = geometry;
      for (int i0 = 1; i0 <= s.steps; i0 += kBufferSteps) {
        const int n = std::min(kBufferSteps, s.steps - i0 + 1);
        const int marched = GatherSteps(df, f, p, k, d, jitter, i0, n, alive, b, 0);
        TestSteps(df, s, p, k, d, b, 0, marched, m);
        if (marched < n) break;
      }
      occlusion = hn::Add(occlusion, DirectionTerm(df, s, k, m));
    }
    return occlusion;
  }
  Direction dirs[kMaxGroup];
  int marched[kMaxGroup];
  for (int dir0 = 0; dir0 < s.directions; dir0 += group) {
    const int count = std::min(group, s.directions - dir0);
    for (int g = 0; g < count; ++g) {
      dirs[g] = direction(dir0 + g);
      MF alive = geometry;
      marched[g] = GatherSteps(df, f, p, k, dirs[g], jitter, 1, s.steps, alive, b, g * s.steps);
    }
    for (int g = 0; g < count; ++g) {
      March m{hn::Zero(df), hn::Zero(df), hn::Zero(df)};
      TestSteps(df, s, p, k, dirs[g], b, g * s.steps, marched[g], m);
      occlusion = hn::Add(occlusion, DirectionTerm(df, s, k, m));
    }
  }
  return occlusion;
}

}  // namespace

// Pixels [x_begin, x_end) of row y of HBAO into out (the row): hbao_pixel on Lanes pixels at
// a time. base_cos/sin: the unrotated direction table (HorizonDirections).
void HbaoSpan(const HorizonFrame& f, const HbaoSettings& s, const float* base_cos,
              const float* base_sin, int y, int x_begin, int x_end, float* HWY_RESTRICT out) {
  const DF df;
  const DI di;
  const int w = f.width;
  const float inv_fx = 1.0f / f.cam.fx, inv_fy = 1.0f / f.cam.fy;
  RowConstants k;
  k.inv_fx = hn::Set(df, inv_fx), k.inv_fy = hn::Set(df, inv_fy);
  k.fx = hn::Set(df, f.cam.fx), k.fy = hn::Set(df, f.cam.fy);
  k.width = hn::Set(df, float(w)), k.height = hn::Set(df, float(f.height));
  k.radius = hn::Set(df, s.radius), k.radius2 = hn::Set(df, s.radius * s.radius);
  k.inv_radius = hn::Set(df, 1.0f / s.radius);
  k.y = y, k.w = w;
  k.small = w < (1 << 23) && f.height < (1 << 23);
  k.mip = MakeMipSampling(df, f);
  const float* depth_row = f.depth + std::size_t(y) * w;
  const float* normal_row = f.normals + 3 * std::size_t(y) * w;
  const float py = float(y) + 0.5f;
  const float spacing = float(2.0 * std::numbers::pi / s.directions);
  const auto seed = std::uint32_t(s.seed);

  ForEachSpanVector(df, x_begin, x_end, [&](int x0, int count) {
    Receiver p;
    p.d = LoadRowPart(df, depth_row + x0, count);
    const MF geometry = hn::Eq(p.d, p.d);  // background is NaN
    if (count == int(hn::Lanes(df))) {
      hn::LoadInterleaved3(df, normal_row + 3 * std::size_t(x0), p.nx, p.ny, p.nz);
    } else {
      HWY_ALIGN float n[3][hn::MaxLanes(df)];
      for (int i = 0; i < int(hn::Lanes(df)); ++i)
        for (int c = 0; c < 3; ++c)
          n[c][i] = normal_row[3 * std::size_t(x0 + std::min(i, count - 1)) + c];
      p.nx = hn::Load(df, n[0]), p.ny = hn::Load(df, n[1]), p.nz = hn::Load(df, n[2]);
    }
    // A tail lane repeats the row's last pixel's data at its own x; its result is dropped.
    p.x = hn::Add(hn::Set(di, x0), hn::Iota(di, 0));
    p.px = PixelCentres(df, x0), p.py = hn::Set(df, py);
    p.ox = hn::Sub(p.px, hn::Set(df, f.cam.cx)), p.oy = hn::Set(df, py - f.cam.cy);
    // horizon_receiver.
    const VF r0x = hn::Mul(p.ox, k.inv_fx), r0y = hn::Neg(hn::Mul(p.oy, k.inv_fy));
    p.n_r0 = hn::Sub(hn::MulAdd(p.nx, r0x, hn::Mul(p.ny, r0y)), p.nz);
    p.ax = hn::Mul(p.nx, k.inv_fx), p.ay = hn::Mul(p.ny, k.inv_fy);
    p.d_n_r0 = hn::Mul(p.d, p.n_r0);
    p.prefilter = hn::Div(p.d_n_r0, hn::Set(df, 1.0f + 12.0f * kUnitRoundoff));
    p.step_scale = hn::Div(k.radius, hn::Mul(p.d, hn::Set(df, float(s.steps))));
    p.grazing = hn::Div(hn::Sqrt(hn::MulAdd(r0x, r0x, hn::MulAdd(r0y, r0y, hn::Set(df, 1.0f)))),
                        hn::Abs(p.n_r0));

    VF result = hn::Set(df, 1.0f);
    if (!hn::AllFalse(df, geometry)) {
      // hbao_pixel_pattern and HorizonDirections::rotated.
      const VF rotation = s.random_rotation ? PixelRandom(df, seed, x0, y, 0) : hn::Zero(df);
      const VF jitter = s.jitter ? PixelRandom(df, seed, x0, y, 1) : hn::Zero(df);
      const VF phi = hn::Mul(rotation, hn::Set(df, spacing));
      const VF occlusion = MarchDirections(df, f, s, p, k, geometry, jitter, hn::Cos(df, phi),
                                           hn::Sin(df, phi), base_cos, base_sin);
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

HWY_EXPORT(HbaoSpan);

Image hbao_simd(const HorizonFrame& f, const HbaoSettings& s, int threads, Progress* progress) {
  const HorizonDirections directions(s.directions);
  return image_from_simd_tiles(
      f.width, f.height, threads, progress, [&](int y, int x0, int x1, float* out) {
        HWY_DYNAMIC_DISPATCH(HbaoSpan)
        (f, s, directions.base_cos(), directions.base_sin(), y, x0, x1, out);
      });
}

}  // namespace aolab
#endif  // HWY_ONCE
