// The preamble and helpers every Highway file shares (the SIMD kernels, prepared normals,
// cosine directions): the per-target passes, the vector types, the unit roundoff and 1/sqrt by
// estimate and Newton step, per-pixel random numbers for a vector of pixels, the background
// rule, a row of pixels in vectors with its tail, and atan2 (Highway 1.0 has only atan).
//
// A Highway file opens with the same two lines and includes this header among its others:
//
//     #undef HWY_TARGET_INCLUDE
//     #define HWY_TARGET_INCLUDE "core/methods/<name>/<name>_simd.cpp"  // the file itself
//     ...
//     #include "core/base/simd-inl.h"
//
// Its kernels stand between HWY_BEFORE_NAMESPACE(); namespace aolab::HWY_NAMESPACE { and
// } HWY_AFTER_NAMESPACE();, where hn and the vector types below are in scope, and its
// HWY_EXPORT and HWY_DYNAMIC_DISPATCH in an #if HWY_ONCE block at its end. What both of those
// read (the file's own types and tables) stands before the kernels in an
// #ifndef AOLAB_<NAME>_SIMD_ONCE_ block, since the file is compiled once per target.
//
// The include of foreach_target.h below, outside the include guard, compiles the file once per
// target: it includes the file again with each HWY_TARGET (its own guard makes it a no-op
// inside those passes), and then leaves the static target for the rest of the first pass. A
// Highway file includes no Highway header itself, and every -inl.h of the project includes this
// one first, so foreach_target.h comes before highway.h whatever the order of a file's includes
// (which clang-format sorts). The rest is included once per target, so it has Highway's
// per-target include guard instead of #pragma once.
//
// The kernels put consecutive pixels of one row in the lanes of a vector. A pixel's lanes
// never interact, and a row is always cut into vectors from x = 0, so a pixel's value does not
// depend on the thread count or on which band computed it.
#ifndef HWY_TARGET_INCLUDE
#error "define HWY_TARGET_INCLUDE as the including file's path before including simd-inl.h"
#endif
#include <hwy/foreach_target.h>

#if defined(AOLAB_BASE_SIMD_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef AOLAB_BASE_SIMD_INL_H_
#undef AOLAB_BASE_SIMD_INL_H_
#else
#define AOLAB_BASE_SIMD_INL_H_
#endif

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

#include <cstdint>
#include <numbers>

HWY_BEFORE_NAMESPACE();
namespace aolab::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

/// The vectors the kernels compute in: float lanes, and int32 and uint32 lanes of the same
/// count (indices, counters, hashes), with their masks.
using DF = hn::ScalableTag<float>;
using DI = hn::RebindToSigned<DF>;
using DU = hn::RebindToUnsigned<DF>;
using VF = hn::Vec<DF>;
using VI = hn::Vec<DI>;
using VU = hn::Vec<DU>;
using MF = hn::Mask<DF>;
using MI = hn::Mask<DI>;
/// Double lanes, and the float and int32 lanes of the same count (the halves of a float
/// vector), for the kernels that compute a step in double.
using DD = hn::ScalableTag<double>;
using DFH = hn::Rebind<float, DD>;
using DIH = hn::Rebind<std::int32_t, DD>;
using VD = hn::Vec<DD>;

/// The float unit roundoff, 2^-24: the kernels' rounding tolerances are multiples of it.
constexpr float kUnitRoundoff = 1.0f / 16777216.0f;

/// 1/sqrt(v) to about 1 ulp less than float's 24 bits: the ~12-bit hardware estimate and one
/// Newton step, 5 cheap operations instead of a square root and a division (each several times
/// slower on every x86 core). v must be > 0 and finite; callers mask the other lanes.
template <class DF>
HWY_INLINE hn::Vec<DF> RecipSqrt(DF df, hn::Vec<DF> v) {
  const auto y = hn::ApproximateReciprocalSqrt(v);
  const auto half_v_y = hn::Mul(hn::Mul(hn::Set(df, 0.5f), v), y);
  return hn::Mul(y, hn::NegMulAdd(half_v_y, y, hn::Set(df, 1.5f)));
}

/// pcg_hash (core/sampling/random.h) on every lane: integer operations only, so the same
/// bits as the scalar hash.
template <class DU>
HWY_INLINE hn::Vec<DU> PcgHash(DU du, hn::Vec<DU> v) {
  const auto state = hn::Add(hn::Mul(v, hn::Set(du, 747796405u)), hn::Set(du, 2891336453u));
  const auto shift = hn::Add(hn::ShiftRight<28>(state), hn::Set(du, 4u));
  const auto word = hn::Mul(hn::Xor(hn::Shr(state, shift), state), hn::Set(du, 277803737u));
  return hn::Xor(hn::ShiftRight<22>(word), word);
}

/// pixel_random(seed, x, y, stream) for the pixels x0, x0 + 1, ... of row y: bit for bit the
/// scalar value (core/sampling/random.h).
template <class DF>
HWY_INLINE hn::Vec<DF> PixelRandom(DF df, std::uint32_t seed, int x0, int y, std::uint32_t stream) {
  const hn::RebindToUnsigned<DF> du;
  // The first hash does not depend on the pixel: once, in scalar code.
  std::uint32_t h0 = seed ^ 0x9E3779B9u;
  {
    const std::uint32_t state = h0 * 747796405u + 2891336453u;
    const std::uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    h0 = (word >> 22u) ^ word;
  }
  auto h = hn::Xor(hn::Set(du, h0), hn::Add(hn::Set(du, std::uint32_t(x0)), hn::Iota(du, 0)));
  h = PcgHash(du, h);
  h = PcgHash(du, hn::Xor(h, hn::Set(du, std::uint32_t(y) * 0x85EBCA6Bu)));
  h = PcgHash(du, hn::Add(h, hn::Set(du, stream * 0xC2B2AE35u)));
  return hn::Mul(hn::ConvertTo(df, hn::BitCast(hn::RebindToSigned<DF>(), hn::ShiftRight<8>(h))),
                 hn::Set(df, 1.0f / 16777216.0f));
}

/// The x coordinates x0, x0 + 1, ... as floats plus 0.5: the pixel centres.
template <class DF>
HWY_INLINE hn::Vec<DF> PixelCentres(DF df, int x0) {
  return hn::Add(hn::Iota(df, float(x0)), hn::Set(df, 0.5f));
}

/// atan2(y, x) in (−π, π], accurate to Highway's atan (a few ulp): atan of the smaller ratio,
/// turned into the right quadrant. atan2(0, 0) = 0. Our own rather than hwy::Atan2 (Highway
/// 1.1+; not in Debian 12's 1.0), so that the bits do not depend on the Highway release, and
/// named apart from it, which argument-dependent lookup would otherwise find too.
template <class DF>
HWY_INLINE hn::Vec<DF> QuadrantAtan2(DF df, hn::Vec<DF> y, hn::Vec<DF> x) {
  const auto ay = hn::Abs(y), ax = hn::Abs(x);
  const auto swap = hn::Gt(ay, ax);
  const auto num = hn::IfThenElse(swap, ax, ay), den = hn::IfThenElse(swap, ay, ax);
  const auto ratio = hn::IfThenElseZero(hn::Gt(den, hn::Zero(df)), hn::Div(num, den));  // in [0, 1]
  auto a = hn::Atan(df, ratio);  // in [0, π/4]
  a = hn::IfThenElse(swap, hn::Sub(hn::Set(df, float(std::numbers::pi / 2)), a), a);
  a = hn::IfThenElse(hn::Lt(x, hn::Zero(df)), hn::Sub(hn::Set(df, float(std::numbers::pi)), a), a);
  return hn::CopySign(a, y);
}

/// Runs body(x0, lanes_valid) over the row's pixels in vectors of Lanes(df): x0 = 0, N, 2N,
/// ...; the last vector may reach past the row (lanes_valid < N), and its extra lanes must
/// read clamped coordinates and be stored with StoreRowPart.
template <class DF, class Body>
HWY_INLINE void ForEachRowVector(DF df, int width, Body body) {
  const int n = int(hn::Lanes(df));
  for (int x0 = 0; x0 < width; x0 += n) body(x0, width - x0 < n ? width - x0 : n);
}

/// Runs body(x0, lanes_valid) over the pixels [x_begin, x_end) of a row in vectors of
/// Lanes(df), as ForEachRowVector; x_begin must be a multiple of Lanes(df) (a tile edge), so
/// that a pixel lands in the same vector whatever the tiling.
template <class DF, class Body>
HWY_INLINE void ForEachSpanVector(DF df, int x_begin, int x_end, Body body) {
  const int n = int(hn::Lanes(df));
  for (int x0 = x_begin; x0 < x_end; x0 += n) body(x0, x_end - x0 < n ? x_end - x0 : n);
}

/// Stores the first `count` lanes of v at out (count ≤ Lanes(df)).
template <class DF>
HWY_INLINE void StoreRowPart(DF df, hn::Vec<DF> v, int count, float* HWY_RESTRICT out) {
  if (count == int(hn::Lanes(df))) {
    hn::StoreU(v, df, out);
  } else {
    HWY_ALIGN float lanes[hn::MaxLanes(df)];
    hn::Store(v, df, lanes);
    for (int i = 0; i < count; ++i) out[i] = lanes[i];
  }
}

/// Loads `count` floats from p (count ≤ Lanes(df)); the other lanes repeat the last one, so a
/// row's tail vector computes real (if duplicated) pixels rather than garbage.
template <class DF>
HWY_INLINE hn::Vec<DF> LoadRowPart(DF df, const float* HWY_RESTRICT p, int count) {
  if (count == int(hn::Lanes(df))) return hn::LoadU(df, p);
  HWY_ALIGN float lanes[hn::MaxLanes(df)];
  for (int i = 0; i < int(hn::Lanes(df)); ++i) lanes[i] = p[i < count ? i : count - 1];
  return hn::Load(df, lanes);
}

}  // namespace aolab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // AOLAB_BASE_SIMD_INL_H_
