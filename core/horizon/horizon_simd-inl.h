// The exact per-sample tangent test (above_tangent_plane, receiver.h) and the depth MIP
// chain's sample index (horizon_sample_index, frame.h) on a vector of lanes: the one SIMD copy
// that HBAO's kernel and the slice kernels (GTAO, the visibility bitmask) share, as their scalar
// code shares receiver.h and frame.h. Included once per target by a kernel's foreach_target
// pass, so it has Highway's per-target include guard instead of #pragma once.
#if defined(AOLAB_HORIZON_SIMD_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef AOLAB_HORIZON_SIMD_INL_H_
#undef AOLAB_HORIZON_SIMD_INL_H_
#else
#define AOLAB_HORIZON_SIMD_INL_H_
#endif

#include <limits>

#include "core/base/simd-inl.h"
#include "core/horizon/frame.h"
#include "core/horizon/receiver.h"

HWY_BEFORE_NAMESPACE();
namespace aolab::HWY_NAMESPACE {

/// The exact test's outcome and the terms a caller reuses.
template <class DF>
struct TangentTest {
  hn::Mask<DF> counts;     ///< the sample lies in front of the tangent plane by more than tol
  hn::Mask<DF> hits;       ///< the sample's ray meets the plane in front of the camera
  hn::Vec<DF> tau;         ///< depth where it meets it (meaningful where `hits`)
  hn::Vec<DF> inv_rs_len;  ///< 1/|rs|, rs the sample's view ray at depth 1
};

/// above_tangent_plane on the lanes of `maybe` (false elsewhere), for a sample at depth
/// `ds` on the view ray rs = (rsx, rsy, −1): d_n_r0 = d·(n·r0) of the receiver, n_rs = n·rs,
/// grazing_p = |r0|/|n·r0|. The tolerance is 2^-24·max(ds, tau)·(kTangentDepthUlps +
/// kTangentNormalUlps·(g_P + g_S)), as in the scalar test.
template <class DF>
HWY_INLINE TangentTest<DF> ExactTangentTest(DF df, hn::Vec<DF> d_n_r0, hn::Vec<DF> n_rs,
                                            hn::Vec<DF> rsx, hn::Vec<DF> rsy, hn::Vec<DF> ds,
                                            hn::Vec<DF> grazing_p, hn::Mask<DF> maybe) {
  const auto zero = hn::Zero(df);
  TangentTest<DF> t;
  t.tau = hn::Div(d_n_r0, n_rs);
  t.hits = hn::And(hn::And(hn::Lt(n_rs, zero), hn::Gt(t.tau, zero)), hn::IsFinite(t.tau));
  const auto rejected = hn::AndNot(hn::Gt(t.tau, ds), t.hits);
  // |rs| ≥ 1; g only scales the tolerance, so the hardware reciprocal estimates will do.
  t.inv_rs_len = RecipSqrt(df, hn::MulAdd(rsx, rsx, hn::MulAdd(rsy, rsy, hn::Set(df, 1.0f))));
  const auto grazing_s =
      hn::Mul(hn::ApproximateReciprocal(t.inv_rs_len), hn::ApproximateReciprocal(hn::Abs(n_rs)));
  const auto tol =
      hn::Mul(hn::Mul(hn::Set(df, kUnitRoundoff), hn::Max(ds, hn::IfThenElse(t.hits, t.tau, ds))),
              hn::MulAdd(hn::Set(df, kTangentNormalUlps), hn::Add(grazing_p, grazing_s),
                         hn::Set(df, kTangentDepthUlps)));
  const auto gap = hn::Sub(
      hn::IfThenElse(t.hits, t.tau, hn::Set(df, std::numeric_limits<float>::infinity())), ds);
  t.counts = hn::And(hn::AndNot(rejected, maybe), hn::Gt(gap, tol));
  return t;
}

/// What horizon_sample_index needs of the frame's depth MIP chain, on every lane.
template <class DF>
struct MipSampling {
  bool on = false;  ///< f.inv_mip_distance > 0
  hn::Vec<DF> inv_q;
  hn::Vec<hn::RebindToSigned<DF>> levels, frame, slot, max_x, max_y;  // max_x: w − 1
};

template <class DF>
HWY_INLINE MipSampling<DF> MakeMipSampling(DF df, const HorizonFrame& f) {
  const hn::RebindToSigned<DF> di;
  MipSampling<DF> m;
  m.on = f.inv_mip_distance > 0.0f;
  m.inv_q = hn::Set(df, f.inv_mip_distance);
  m.levels = hn::Set(di, f.mip.levels);
  m.frame = hn::Set(di, f.mip.frame), m.slot = hn::Set(di, f.mip.slot);
  m.max_x = hn::Set(di, f.width - 1), m.max_y = hn::Set(di, f.height - 1);
  return m;
}

/// horizon_sample_index with the MIP chain on every lane: the level of a sample `distance` pixels
/// from P, its texel's index in the chain, and (sx, sy) snapped to the level's pixel
/// (depth_mip_pixel). A lane that has left the image holds texel (0, 0), inside every level.
template <class DF>
HWY_INLINE hn::Vec<hn::RebindToSigned<DF>> MipSampleIndex(DF, const MipSampling<DF>& m,
                                                          hn::Vec<DF> distance,
                                                          hn::Vec<hn::RebindToSigned<DF>>& sx,
                                                          hn::Vec<hn::RebindToSigned<DF>>& sy) {
  const hn::RebindToSigned<DF> di;
  // depth_mip_level: the exponent of r/q, clamped to [0, levels].
  const auto ratio = hn::Mul(distance, m.inv_q);
  auto level = hn::Sub(hn::ShiftRight<23>(hn::BitCast(di, ratio)), hn::Set(di, 127));
  level = hn::Min(hn::Max(level, hn::Zero(di)), m.levels);
  const auto bx = hn::Shr(sx, level), by = hn::Shr(sy, level);
  // The level's offset and width (DepthMipLayout): frame + (l − 1)·slot for l ≥ 1, and
  // ceil(w / 2^l) = (w − 1 + 2^l) >> l.
  const auto one = hn::Set(di, 1), size = hn::Shl(one, level);
  const auto offset = hn::IfThenElseZero(hn::Gt(level, hn::Zero(di)),
                                         hn::Add(m.frame, hn::Mul(hn::Sub(level, one), m.slot)));
  const auto width = hn::Shr(hn::Add(m.max_x, size), level);
  const auto index = hn::Add(offset, hn::Add(hn::Mul(by, width), bx));
  const auto half = hn::ShiftRight<1>(size);
  sx = hn::Min(hn::Add(hn::Shl(bx, level), half), m.max_x);
  sy = hn::Min(hn::Add(hn::Shl(by, level), half), m.max_y);
  return index;
}

}  // namespace aolab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // AOLAB_HORIZON_SIMD_INL_H_
