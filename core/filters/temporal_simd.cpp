// The accumulation step's SIMD kernel (docs/temporal.md, "Kernel"): accumulate_pixel on a
// vector of consecutive pixels of one row, in double lanes with the float operations of the
// scalar code done on float lanes of the same count, each in the same order and with no fused
// multiply-add, so that every pixel gets the scalar code's bits. The history's taps are
// gathered; a tap the scalar code does not read (weight 0) or rejects adds an exact 0 to the
// sums, which leaves them as they were. Per vector, the lanes that leave the common case
// (background, non-finite motion, a bilinear footprint not wholly inside the image) are done
// again by accumulate_pixel, and so are the image's first and last rows and the vectors
// touching its first or last column (a 3x3 neighbourhood cut by the edge).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/filters/temporal_simd.cpp"

#include <cstddef>
#include <cstdint>
#include <limits>

#include "core/base/simd-inl.h"
#include "core/filters/temporal_pixel.h"

HWY_BEFORE_NAMESPACE();
namespace aolab::HWY_NAMESPACE {

/// A float mask as a double mask of the same lanes (Highway 1.0 rebinds masks only between
/// lanes of one size).
HWY_INLINE hn::Mask<DD> Widen(hn::Mask<DFH> m) {
  const DFH dh;
  return hn::Gt(hn::PromoteTo(DD(), hn::IfThenElseZero(m, hn::Set(dh, 1.0f))), hn::Zero(DD()));
}

/// The current frame's 3x3 neighbourhood of the lanes' pixels (clamp_range): its range over
/// the geometry pixels, for Variance narrowed to mean ± γσ. The centre is geometry, and the
/// neighbours in the same order as the scalar loop, rows then columns.
HWY_INLINE void ClampRange(const TemporalFrame& f, int x, int y, VD& lo, VD& hi) {
  const DD dd;
  const DFH dh;
  const auto background = hn::Set(dh, f.g.background_depth);
  lo = hn::PromoteTo(dd, hn::LoadU(dh, &f.ao(x, y)));
  hi = lo;
  VD sum = hn::Zero(dd), sum2 = hn::Zero(dd), count = hn::Zero(dd);
  for (int yy = y - 1; yy <= y + 1; ++yy)
    for (int xx = x - 1; xx <= x + 1; ++xx) {
      const auto d = hn::LoadU(dh, &f.g.depth(xx, yy));
      const auto geometry =
          Widen(hn::And(hn::And(hn::IsFinite(d), hn::Gt(d, hn::Zero(dh))), hn::Lt(d, background)));
      const VD v = hn::PromoteTo(dd, hn::LoadU(dh, &f.ao(xx, yy)));
      lo = hn::IfThenElse(geometry, hn::Min(lo, v), lo);
      hi = hn::IfThenElse(geometry, hn::Max(hi, v), hi);
      sum = hn::Add(sum, hn::IfThenElseZero(geometry, v));
      sum2 = hn::Add(sum2, hn::IfThenElseZero(geometry, hn::Mul(v, v)));
      count = hn::Add(count, hn::IfThenElseZero(geometry, hn::Set(dd, 1.0)));
    }
  if (TemporalClamp(f.settings.clamp) != TemporalClamp::Variance) return;
  const VD mean = hn::Div(sum, count);
  const VD sigma =
      hn::Sqrt(hn::Max(hn::Zero(dd), hn::Sub(hn::Div(sum2, count), hn::Mul(mean, mean))));
  const VD spread = hn::Mul(hn::Set(dd, double(f.settings.variance_gamma)), sigma);
  lo = hn::Max(lo, hn::Sub(mean, spread));
  hi = hn::Min(hi, hn::Add(mean, spread));
}

/// What the taps kept give (reproject): the weighted sum, the sum of weights and the
/// shortest length (+inf when none is kept).
struct Taps {
  VD sum, wsum, length;
};

/// The four bilinear taps of the lanes' footprints, top-left at (x0, y0) (int lanes, inside
/// the image with their neighbours to the right and below), weights `w`; d and n are the
/// current pixel's depth and prepared normal.
HWY_INLINE Taps GatherTaps(const TemporalFrame& f, hn::Vec<DIH> x0, hn::Vec<DIH> y0,
                           const VD (&w)[4], hn::Vec<DFH> d, const hn::Vec<DFH> (&n)[3]) {
  const DD dd;
  const DFH dh;
  const DIH di;
  const TemporalHistory& h = f.history;
  const TemporalSettings& s = f.settings;
  const auto width = hn::Set(di, h.width());
  const auto tolerance = hn::Mul(hn::Set(dh, s.depth_tolerance), d);
  Taps out{hn::Zero(dd), hn::Zero(dd), hn::Set(dd, std::numeric_limits<double>::infinity())};
  for (int t = 0; t < 4; ++t) {
    const auto at =
        hn::Add(hn::Mul(hn::Add(y0, hn::Set(di, t >> 1)), width), hn::Add(x0, hn::Set(di, t & 1)));
    const auto hd = hn::GatherIndex(dh, h.depth.data(), at);
    auto keep = hn::Le(hn::Abs(hn::Sub(hd, d)), tolerance);
    if (s.normal_tolerance > -1.0f) {
      const auto at3 = hn::Mul(at, hn::Set(di, 3));
      const float* normals = h.normal.data();
      const auto cosine = hn::Add(hn::Add(hn::Mul(hn::GatherIndex(dh, normals, at3), n[0]),
                                          hn::Mul(hn::GatherIndex(dh, normals + 1, at3), n[1])),
                                  hn::Mul(hn::GatherIndex(dh, normals + 2, at3), n[2]));
      keep = hn::And(keep, hn::Ge(cosine, hn::Set(dh, s.normal_tolerance)));
    }
    const auto kept = hn::And(Widen(keep), hn::Ne(w[t], hn::Zero(dd)));
    const VD ao = hn::PromoteTo(dd, hn::GatherIndex(dh, h.ao.data(), at));
    const VD length = hn::PromoteTo(dd, hn::GatherIndex(dh, h.length.data(), at));
    out.sum = hn::Add(out.sum, hn::IfThenElseZero(kept, hn::Mul(w[t], ao)));
    out.length = hn::IfThenElse(kept, hn::Min(out.length, length), out.length);
    out.wsum = hn::Add(out.wsum, hn::IfThenElseZero(kept, w[t]));
  }
  return out;
}

/// The lanes' pixels x, x + 1, ... of row y (inside the image's border); returns the mask of
/// the lanes it did not do (accumulate_pixel does them).
HWY_INLINE hn::Mask<DD> Vector(const TemporalFrame& f, int x, int y) {
  const DD dd;
  const DFH dh;
  const DIH di;
  const TemporalSettings& s = f.settings;
  const int w = f.g.width(), h = f.g.height();
  const auto d = hn::LoadU(dh, &f.g.depth(x, y));
  const auto c = hn::LoadU(dh, &f.ao(x, y));
  hn::Vec<DFH> mx, my;
  hn::LoadInterleaved2(dh, &f.motion(x, y, 0), mx, my);
  const auto geometry = hn::And(hn::And(hn::IsFinite(d), hn::Gt(d, hn::Zero(dh))),
                                hn::Lt(d, hn::Set(dh, f.g.background_depth)));
  const auto finite = hn::And(hn::IsFinite(mx), hn::IsFinite(my));
  // The previous-frame position and its footprint, in double as reproject has them.
  const VD px = hn::Add(hn::Iota(dd, double(x)), hn::PromoteTo(dd, mx));
  const VD py = hn::Add(hn::Set(dd, double(y)), hn::PromoteTo(dd, my));
  const VD fx0 = hn::Floor(px), fy0 = hn::Floor(py);
  const auto inside =
      hn::And(hn::And(hn::Ge(fx0, hn::Zero(dd)), hn::Lt(fx0, hn::Set(dd, double(w - 1)))),
              hn::And(hn::Ge(fy0, hn::Zero(dd)), hn::Lt(fy0, hn::Set(dd, double(h - 1)))));
  const auto common = hn::And(Widen(hn::And(geometry, finite)), inside);
  // Lanes outside the common case read the pixel's own place (always in the image).
  const VD cx0 = hn::IfThenElse(common, fx0, hn::Iota(dd, double(x)));
  const VD cy0 = hn::IfThenElse(common, fy0, hn::Set(dd, double(y)));
  const VD fx = hn::Sub(px, fx0), fy = hn::Sub(py, fy0);
  const VD one = hn::Set(dd, 1.0);
  const VD weights[4] = {hn::Mul(hn::Sub(one, fx), hn::Sub(one, fy)), hn::Mul(fx, hn::Sub(one, fy)),
                         hn::Mul(hn::Sub(one, fx), fy), hn::Mul(fx, fy)};
  hn::Vec<DFH> normal[3];
  hn::LoadInterleaved3(dh,
                       f.normals.data() + (std::size_t(y) * std::size_t(w) + std::size_t(x)) * 3,
                       normal[0], normal[1], normal[2]);
  const Taps taps = GatherTaps(f, hn::DemoteTo(di, cx0), hn::DemoteTo(di, cy0), weights, d, normal);
  const auto found = hn::Ne(taps.wsum, hn::Zero(dd));
  VD past = hn::Div(taps.sum, taps.wsum);
  if (TemporalClamp(s.clamp) != TemporalClamp::Off) {
    VD lo, hi;
    ClampRange(f, x, y, lo, hi);
    past = hn::Min(hn::Max(past, lo), hi);  // std::clamp: lo <= hi, neither NaN
  }
  const VD weight = hn::Max(hn::Set(dd, double(s.alpha)), hn::Div(one, hn::Add(taps.length, one)));
  const VD current = hn::PromoteTo(dd, c);
  const VD blended = hn::Add(past, hn::Mul(weight, hn::Sub(current, past)));
  // Lengths are whole numbers below 2^24: the double sum is the scalar float sum.
  const VD length = hn::Min(hn::Add(taps.length, one), hn::Set(dd, double(s.max_history)));
  const VD accumulated = hn::IfThenElse(found, blended, current);  // (a float, exactly)
  hn::StoreU(hn::DemoteTo(dh, accumulated), dh, &f.accumulated(x, y));
  hn::StoreU(hn::DemoteTo(dh, hn::IfThenZeroElse(found, one)), dh, &f.disoccluded(x, y));
  hn::StoreU(hn::DemoteTo(dh, hn::IfThenElse(found, length, one)), dh, &f.length(x, y));
  hn::StoreU(d, dh, &f.depth(x, y));
  return hn::Not(common);
}

void AccumulateRow(const TemporalFrame& f, int y) {
  const DD dd;
  const int w = f.g.width(), n = int(hn::Lanes(dd));
  const bool vectors =
      !f.history.empty() && y >= 1 && y + 1 < f.g.height() && f.g.depth.channels == 1;
  int x = 0;
  if (vectors) {
    for (; x < 1; ++x) accumulate_pixel(f, x, y);
    for (; x + n + 1 <= w; x += n) {
      const auto redo = Vector(f, x, y);
      if (hn::AllFalse(dd, redo)) continue;
      HWY_ALIGN double lanes[hn::MaxLanes(dd)];
      hn::Store(hn::VecFromMask(dd, redo), dd, lanes);
      for (int i = 0; i < n; ++i)
        if (lanes[i] != 0.0) accumulate_pixel(f, x + i, y);
    }
  }
  for (; x < w; ++x) accumulate_pixel(f, x, y);
}

}  // namespace aolab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace aolab {

HWY_EXPORT(AccumulateRow);

void accumulate_row_simd(const TemporalFrame& f, int y) {
  HWY_DYNAMIC_DISPATCH(AccumulateRow)(f, y);
}

}  // namespace aolab
#endif  // HWY_ONCE
