// The visibility bitmask's SIMD kernel: the scalar per-pixel code of bitmask.cpp (the oracle
// it is tested against) on Lanes consecutive pixels of a row at once, compiled by Highway for
// every target and dispatched at run time. Every setting is supported. The slice set-up, the
// march and the tangent test are GTAO's SIMD ones (core/horizon/slice_simd-inl.h).
//
// What it does differently (docs/methods/bitmask.md, "SIMD kernel"):
// - a slice's sector mask is one 32-bit word per lane (two for more than 32 sectors), a
//   sample's sectors are set with shifts, and the uniform weighting counts the free sectors
//   with a per-lane population count;
// - a sample's front and back angles are atan2(|X·t|, X·v) of the segment's ends X in the
//   slice's frame (v, the slice axis, its in-plane tangent t), in float, and the sectors they
//   fall in are floor((θ − n + π/2)/δ): no table search; the scalar code compares cosines in
//   double against the sector edges' cosines, so the two disagree only for an end within a
//   float rounding of a sector edge;
// - an end far along the segment (t > 1, up to the unbounded thickness) is taken as
//   X/t = D/t + u, so no square of a huge t is ever formed.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/methods/bitmask/bitmask_simd.cpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <vector>

#include "core/base/parallel.h"
#include "core/base/simd-inl.h"
#include "core/base/simd_tiles.h"
#include "core/horizon/slice.h"
#include "core/horizon/slice_simd-inl.h"
#include "core/methods/bitmask/bitmask.h"
#include "core/methods/bitmask/bitmask_shared.h"

HWY_BEFORE_NAMESPACE();
namespace aolab::HWY_NAMESPACE {
namespace {
using namespace slice_simd;

// A slice's mask on every lane: sectors 0–31 in lo, 32–63 in hi (zero unless kWide).
struct Mask {
  VU lo, hi;
};

// (1 << k) − 1 for k in [0, 32] on every lane (a shift by 32 is not defined).
HWY_INLINE VU Below32(VI k) {
  const DU du;
  const DI di;
  const VU one = hn::Set(du, 1u);
  const VU shifted = hn::Shl(one, hn::BitCast(du, hn::Min(k, hn::Set(di, 31))));
  return hn::IfThenElse(hn::RebindMask(du, hn::Gt(k, hn::Set(di, 31))), hn::Set(du, ~0u),
                        hn::Sub(shifted, one));
}

// The sectors below k, k in [0, 64].
template <bool kWide>
HWY_INLINE Mask Below(VI k) {
  const DI di;
  const DU du;
  if (!kWide) return {Below32(k), hn::Zero(du)};
  const VI k32 = hn::Set(di, 32);
  return {Below32(hn::Min(k, k32)), Below32(hn::Min(hn::Max(hn::Sub(k, k32), hn::Zero(di)), k32))};
}

struct Params {
  const BitmaskSettings& s;
  float thickness;  // T = thickness·R (inf where float cannot hold it: the unbounded limit)
  float radius2;
  float back_scale;  // 1/max(T, 1)
};

// α − n for the point X(t) = D + t·u of a sample's segment on `side`: α is its signed angle
// from v in the slice plane (θ ∈ [0, π] on side 0, −θ on side 1, with cos θ = (X·v)/|X − a(a·X)|
// as the scalar code), n the projected normal's. It is taken as one atan2 of X in the frame of
// proj n, (X·v, ±|X·t|) turned by −n with cos n and sin n, so that the sectors' edges, which
// lie at fixed angles from n, are placed without n's own rounding; the result is unwrapped
// to α − n's range, [−π/2, 3π/2] on side 0 and [−3π/2, π/2] on side 1. For t > 1 the point is
// scaled by 1/t (the angle does not change), so t = ∞ gives u's own angle.
HWY_INLINE VF AngleFromNormal(DF df, const Slice& sl, const Pixels& p, const Offset& o, VF ux,
                              VF uy, VF uz, VF scale, VF t_scaled, int side) {
  const VF x = hn::MulAdd(o.x, scale, hn::Mul(ux, t_scaled));
  const VF y = hn::MulAdd(o.y, scale, hn::Mul(uy, t_scaled));
  const VF z = hn::MulAdd(o.z, scale, hn::Mul(uz, t_scaled));
  const VF along = hn::MulAdd(x, p.vx, hn::MulAdd(y, p.vy, hn::Mul(z, p.vz)));
  const VF off_abs = hn::Abs(hn::MulAdd(x, sl.tx, hn::MulAdd(y, sl.ty, hn::Mul(z, sl.tz))));
  const VF off = side == 0 ? off_abs : hn::Neg(off_abs);
  const VF rx = hn::MulAdd(sl.cos_n, along, hn::Mul(sl.sin_n, off));
  const VF ry = hn::MulSub(sl.cos_n, off, hn::Mul(sl.sin_n, along));
  const VF rel = QuadrantAtan2(df, ry, rx);
  const VF half_pi = hn::Set(df, float(std::numbers::pi / 2));
  const VF two_pi = hn::Set(df, float(2 * std::numbers::pi));
  return side == 0 ? hn::IfThenElse(hn::Lt(rel, hn::Neg(half_pi)), hn::Add(rel, two_pi), rel)
                   : hn::IfThenElse(hn::Gt(rel, half_pi), hn::Sub(rel, two_pi), rel);
}

// pos(α) = #{i : φ_i ≤ α} of the 2N + 1 sector edges and centres φ_i = n − π/2 + iδ, from
// α − n.
HWY_INLINE VI PointCount(DF df, VF rel, VF inv_delta, VF top) {
  const DI di;
  const VF half_pi = hn::Set(df, float(std::numbers::pi / 2));
  const VF u = hn::Mul(hn::Add(rel, half_pi), inv_delta);
  const VF clamped = hn::Min(hn::Max(u, hn::Set(df, -1.0f)), top);
  return hn::Add(hn::ConvertTo(di, hn::Floor(clamped)), hn::Set(di, 1));
}

// sample_bits on the lanes of `visited`, OR-ed into the slice's mask.
template <bool kWide>
HWY_INLINE void SampleBits(DF df, const Params& q, const Row& k, const Pixels& p, const Slice& sl,
                           int side, MF visited, VI sx, VI sy, VF ds, Mask& mask) {
  const DI di;
  const DU du;
  const BitmaskSettings& s = q.s;
  const VF zero = hn::Zero(df), one = hn::Set(df, 1.0f);
  const Offset o = sample_offset(df, k, p, sx, sy, ds);
  MF ok = visited;
  if (s.radius_clip == int(BitmaskRadiusClip::Cut))
    ok = hn::And(ok, hn::Le(o.r2, hn::Set(df, q.radius2)));
  ok = above_tangent_plane(df, k, p, ok, o.qx, o.qy, ds);
  if (hn::AllFalse(df, ok)) return;
  // The segment's direction u: −v (the paper's) or the sample's own view ray (EEVEE's).
  VF ux, uy, uz;
  if (s.back_direction == int(BitmaskBackDirection::View)) {
    ux = hn::Neg(p.vx), uy = hn::Neg(p.vy), uz = hn::Neg(p.vz);
  } else {
    const VF rx = hn::Mul(hn::Add(p.ox, o.qx), k.inv_fx);
    const VF ry = hn::Neg(hn::Mul(hn::Add(p.oy, o.qy), k.inv_fy));
    const VF inv = RecipSqrt(df, hn::MulAdd(rx, rx, hn::MulAdd(ry, ry, one)));
    ux = hn::Mul(rx, inv), uy = hn::Mul(ry, inv), uz = hn::Neg(inv);
  }
  VF t0 = zero, t1 = hn::Set(df, q.thickness);
  if (s.radius_clip == int(BitmaskRadiusClip::Sphere)) {
    // |D + t u|² = R²: t² + 2(D·u)t + (|D|² − R²) = 0, roots without cancellation.
    const VF du_ = hn::MulAdd(o.x, ux, hn::MulAdd(o.y, uy, hn::Mul(o.z, uz)));
    const VF c = hn::Sub(o.r2, hn::Set(df, q.radius2));
    const VF disc = hn::MulSub(du_, du_, c);
    ok = hn::And(ok, hn::Gt(disc, zero));
    if (hn::AllFalse(df, ok)) return;
    const VF root = hn::Sub(hn::Neg(du_), hn::CopySign(hn::Sqrt(hn::Max(disc, zero)), du_));
    const VF other = hn::Div(c, hn::IfThenElse(ok, root, one));
    t0 = hn::Max(t0, hn::Min(root, other));
    t1 = hn::Min(t1, hn::Max(root, other));
    ok = hn::And(ok, hn::Ge(t1, t0));
    if (hn::AllFalse(df, ok)) return;
  }
  // The front end at t0 (t0 = 0 unless the sphere clipped it), the back end at t1; an end at
  // t > 1 scaled by 1/t (q's constants where t1 = T for every lane).
  VF scale0 = one, scale1 = hn::Set(df, q.back_scale);
  if (s.radius_clip == int(BitmaskRadiusClip::Sphere)) {
    scale0 = hn::Div(one, hn::Max(t0, one));
    scale1 = hn::Div(one, hn::Max(t1, one));
  }
  const VF front = AngleFromNormal(df, sl, p, o, ux, uy, uz, scale0, hn::Min(t0, one), side);
  const VF back = AngleFromNormal(df, sl, p, o, ux, uy, uz, scale1, hn::Min(t1, one), side);
  // Side 0: [a, b] = [θ_front, θ_back]; side 1: [−θ_back, −θ_front]. An empty interval (T = 0,
  // or no direction at all) marks nothing.
  const VF a = side == 0 ? front : back;
  const VF b = side == 0 ? back : front;
  ok = hn::And(ok, hn::Lt(a, b));
  if (hn::AllFalse(df, ok)) return;
  const VF inv_delta = hn::Set(df, float(2.0 * s.sectors / std::numbers::pi));
  const VF top = hn::Set(df, float(2 * s.sectors + 1));
  const VI pos_a = PointCount(df, a, inv_delta, top);
  const VI pos_b = PointCount(df, b, inv_delta, top);
  const VI one_i = hn::Set(di, 1);
  VI first, last;  // interval_bits
  switch (BitmaskRounding(s.rounding)) {
    case BitmaskRounding::Touch:
      first = hn::Sub(hn::ShiftRight<1>(hn::Add(pos_a, one_i)), one_i);
      last = hn::ShiftRight<1>(hn::Add(pos_b, one_i));
      break;
    case BitmaskRounding::Half:
      first = hn::ShiftRight<1>(pos_a);
      last = hn::ShiftRight<1>(pos_b);
      break;
    default:  // Cover
      first = hn::ShiftRight<1>(hn::Add(pos_a, one_i));
      last = hn::Sub(hn::ShiftRight<1>(hn::Add(pos_b, one_i)), one_i);
      break;
  }
  first = hn::Max(first, hn::Zero(di));
  last = hn::Min(hn::Max(last, hn::Zero(di)), hn::Set(di, s.sectors));
  // Below(last) ⊆ Below(first) when last ≤ first: then no bit.
  const Mask below_last = Below<kWide>(last), below_first = Below<kWide>(first);
  const auto ok_u = hn::RebindMask(du, ok);
  mask.lo = hn::Or(mask.lo, hn::IfThenElseZero(ok_u, hn::AndNot(below_first.lo, below_last.lo)));
  if (kWide)
    mask.hi = hn::Or(mask.hi, hn::IfThenElseZero(ok_u, hn::AndNot(below_first.hi, below_last.hi)));
}

template <bool kWide>
void BitmaskSpanT(const SliceFrame& f, const Params& q, const float* base_cos,
                  const float* base_sin, const float* cos_edge, const float* sin_edge, int y,
                  int x_begin, int x_end, float* HWY_RESTRICT out) {
  const DF df;
  const DU du;
  const DI di;
  const BitmaskSettings& s = q.s;
  const Row k = make_row(df, f, y);
  const VF zero = hn::Zero(df), one = hn::Set(df, 1.0f);
  const VF half_pi = hn::Set(df, float(std::numbers::pi / 2));
  const VF quarter = hn::Set(df, 0.25f);
  ForEachSpanVector(df, x_begin, x_end, [&](int x0, int count) {
    const Pixels p = load_pixels(df, f, k, x0, count, s.seed, s.random_rotation, s.jitter,
                                 2 * s.slices, s.radius, s.steps);
    VF result = one;
    if (!hn::AllFalse(df, p.geometry)) {
      VF visible = zero, open = zero, mean = zero;
      for (int slice = 0; slice < s.slices; ++slice) {
        Slice sl = make_slice(df, k, p, base_cos[slice], base_sin[slice]);
        sl.active = p.geometry;  // the bitmask marches slices with |proj n| = 0 too
        // The paper's Algorithm 1: one mask per slice, OR-ed by every sample of both sides.
        Mask mask{hn::Zero(du), hn::Zero(du)};
        march_sides(df, f, k, p, sl, s.steps, [&](int side, MF visited, VI sx, VI sy, VF ds) {
          SampleBits<kWide>(df, q, k, p, sl, side, visited, sx, sy, ds, mask);
        });
        VF slice_visible, slice_open;
        if (s.weighting == int(BitmaskWeighting::Uniform)) {
          // Algorithm 1: the fraction of free sectors, 1 − bitCount(b)/N.
          VU occupied = hn::PopulationCount(mask.lo);
          if (kWide) occupied = hn::Add(occupied, hn::PopulationCount(mask.hi));
          const VF free =
              hn::Sub(hn::Set(df, float(s.sectors)), hn::ConvertTo(df, hn::BitCast(di, occupied)));
          slice_visible = hn::Div(free, hn::Set(df, float(s.sectors)));
          slice_open = one;
        } else {
          // sector_weights: A(φ_j) at the edges φ_j = n − π/2 + jπ/N, with
          // cos(2φ_j − n) = −(cos n cos 2jπ/N − sin n sin 2jπ/N); the free and the total sums
          // take the same operations, so an empty mask gives the same bits for both.
          slice_visible = zero, slice_open = zero;
          VF previous = zero;
          const VF edge_step = hn::Set(df, float(std::numbers::pi / s.sectors));
          const VF base = hn::Sub(sl.n, half_pi);
          for (int j = 0; j <= s.sectors; ++j) {
            const VF phi = hn::MulAdd(hn::Set(df, float(j)), edge_step, base);
            const VF cos_2phi_n = hn::MulSub(hn::Set(df, sin_edge[j]), sl.sin_n,
                                             hn::Mul(hn::Set(df, cos_edge[j]), sl.cos_n));
            const VF a = hn::Mul(
                quarter, hn::MulAdd(hn::Add(phi, phi), sl.sin_n, hn::Sub(sl.cos_n, cos_2phi_n)));
            const VF signed_a = hn::IfThenElse(hn::Lt(phi, zero), hn::Neg(a), a);
            if (j > 0) {
              const VF w = hn::Sub(signed_a, previous);
              const int bit = j - 1;
              const VU word = bit < 32 ? mask.lo : mask.hi;
              const auto free =
                  hn::RebindMask(df, hn::Not(hn::TestBit(word, hn::Set(du, 1u << (bit & 31)))));
              slice_open = hn::Add(slice_open, w);
              slice_visible = hn::Add(slice_visible, hn::IfThenElseZero(free, w));
            }
            previous = signed_a;
          }
        }
        visible = hn::MulAdd(sl.length, slice_visible, visible);
        open = hn::MulAdd(sl.length, slice_open, open);
        mean = s.weighting == int(BitmaskWeighting::Uniform)
                   ? hn::Add(mean, slice_visible)
                   : hn::MulAdd(sl.length, slice_visible, mean);
      }
      VF ao;
      if (s.normalization == int(BitmaskNormalization::Slices)) {
        ao = hn::Div(mean, hn::Set(df, float(s.slices)));
      } else {
        const MF has_open = hn::Gt(open, zero);
        ao = hn::IfThenElse(has_open, hn::Div(visible, hn::IfThenElse(has_open, open, one)), one);
      }
      result = hn::IfThenElse(p.geometry, hn::Min(hn::Max(ao, zero), one), one);
    }
    StoreRowPart(df, result, count, out + x0);
  });
}

}  // namespace

// Pixels [x_begin, x_end) of row y of the bitmask into out (the row): bitmask_pixel on Lanes
// pixels at a time. base_cos/sin: the unrotated table of 2·slices directions; cos_edge and
// sin_edge: cos and sin of 2jπ/N, j = 0 … N.
void BitmaskSpan(const SliceFrame& f, const BitmaskSettings& s, float thickness, float radius2,
                 const float* base_cos, const float* base_sin, const float* cos_edge,
                 const float* sin_edge, int y, int x_begin, int x_end, float* HWY_RESTRICT out) {
  const Params q{s, thickness, radius2, 1.0f / std::max(thickness, 1.0f)};
  if (s.sectors > 32)
    BitmaskSpanT<true>(f, q, base_cos, base_sin, cos_edge, sin_edge, y, x_begin, x_end, out);
  else
    BitmaskSpanT<false>(f, q, base_cos, base_sin, cos_edge, sin_edge, y, x_begin, x_end, out);
}

}  // namespace aolab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace aolab {

HWY_EXPORT(BitmaskSpan);

Image bitmask_simd(const SliceFrame& f, const BitmaskSettings& s, int threads, Progress* progress) {
  const HorizonDirections directions(2 * s.slices);
  std::vector<float> cos_edge, sin_edge;  // SectorTables' cos and sin of 2jπ/N
  for (int j = 0; j <= s.sectors; ++j) {
    cos_edge.push_back(float(std::cos(2.0 * std::numbers::pi * j / s.sectors)));
    sin_edge.push_back(float(std::sin(2.0 * std::numbers::pi * j / s.sectors)));
  }
  // T = thickness·R in double, as the scalar code; beyond float it is the unbounded limit.
  const double thickness = double(s.thickness) * double(s.radius);
  const float t = thickness > 3e38 ? std::numeric_limits<float>::infinity() : float(thickness);
  const float radius2 = s.radius * s.radius;
  return image_from_simd_tiles(f.width, f.height, threads, progress,
                               [&](int y, int x0, int x1, float* out) {
                                 HWY_DYNAMIC_DISPATCH(BitmaskSpan)
                                 (f, s, t, radius2, directions.base_cos(), directions.base_sin(),
                                  cos_edge.data(), sin_edge.data(), y, x0, x1, out);
                               });
}

}  // namespace aolab
#endif  // HWY_ONCE
