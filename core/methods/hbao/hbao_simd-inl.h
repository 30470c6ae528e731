// HBAO's exact per-sample tangent test (hbao_above_tangent_plane) on a vector of lanes: the one
// SIMD copy that HBAO's kernel and GTAO's slice kernel (GTAO, the visibility bitmask) share, as
// their scalar code shares hbao.h's. Included once per target by a kernel's foreach_target
// pass, so it has Highway's per-target include guard instead of #pragma once.
#if defined(AOLAB_HBAO_SIMD_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef AOLAB_HBAO_SIMD_INL_H_
#undef AOLAB_HBAO_SIMD_INL_H_
#else
#define AOLAB_HBAO_SIMD_INL_H_
#endif

#include <limits>

#include "core/base/simd-inl.h"
#include "core/methods/hbao/hbao.h"

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

/// hbao_above_tangent_plane on the lanes of `maybe` (false elsewhere), for a sample at depth
/// `ds` on the view ray rs = (rsx, rsy, −1): d_n_r0 = d·(n·r0) of the receiver, n_rs = n·rs,
/// grazing_p = |r0|/|n·r0|. The tolerance is 2^-24·max(ds, tau)·(kHbaoDepthUlps +
/// kHbaoNormalUlps·(g_P + g_S)), as in the scalar test.
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
              hn::MulAdd(hn::Set(df, kHbaoNormalUlps), hn::Add(grazing_p, grazing_s),
                         hn::Set(df, kHbaoDepthUlps)));
  const auto gap = hn::Sub(
      hn::IfThenElse(t.hits, t.tau, hn::Set(df, std::numeric_limits<float>::infinity())), ds);
  t.counts = hn::And(hn::AndNot(rejected, maybe), hn::Gt(gap, tol));
  return t;
}

}  // namespace aolab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // AOLAB_HBAO_SIMD_INL_H_
