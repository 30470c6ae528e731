// Chebyshev AO's SIMD kernel: the two passes of chebyshev.cpp (the oracle it is tested
// against) on consecutive pixels of a row at once, compiled by Highway for every target and
// dispatched at run time. Every setting is supported, and every lane performs exactly the
// scalar pixel's operations in the same order, so the result has the same bits:
// - horizontal pass (float): the taps −r … r of a column summed in order, as the scalar
//   loop does ("taps outer, columns inner"), with the columns in the lanes; near the image
//   border, where a column's segment is shorter than r, the taps beyond it are masked to
//   zero (adding +0 to a sum that started at +0 changes no bit);
// - vertical pass (double): each row's sums shifted onto the receiver's depth and summed over
//   −ry … ry in order, the moments and eq. 3 with its bias and range check evaluated in
//   double as chebyshev_visibility does, std::max/min/clamp written as the comparisons they
//   are (x86's max returns its second operand for ±0, std::max its first);
// - no fused multiply-add: GCC would contract Highway's Mul followed by Add into one (its
//   default -ffp-contract=fast), which rounds once where the scalar code rounds twice; the
//   pragma below turns that off for this file (the scalar build, without -march, has no FMA).
// What it does differently: the nearest valid pixel of every column (the horizontal pass's
// reference when a pixel is background) is found once per frame rather than once per level
// and row; the vertical pass skips vectors that hold no receiver of the level; the visibility
// is computed in the vertical pass instead of a third pass over the moments.
#pragma GCC optimize("fp-contract=off")
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/methods/chebyshev/chebyshev_simd.cpp"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "core/base/parallel.h"
#include "core/base/simd-inl.h"
#include "core/methods/chebyshev/chebyshev_shared.h"

HWY_BEFORE_NAMESPACE();
namespace aolab::HWY_NAMESPACE {
namespace {

// `count` floats of `row` from `x` on, as a vector, 0 outside [0, w): the taps of a border
// vector that reach past the row's ends (those lanes are masked by the caller).
HWY_INLINE VF LoadInRow(DF df, const float* HWY_RESTRICT row, int x, int w) {
  const int n = int(hn::Lanes(df));
  if (x >= 0 && x + n <= w) return hn::LoadU(df, row + x);
  HWY_ALIGN float lanes[hn::MaxLanes(df)];
  for (int i = 0; i < n; ++i) lanes[i] = x + i >= 0 && x + i < w ? row[x + i] : 0.0f;
  return hn::Load(df, lanes);
}

// One tap of the horizontal pass for a vector of columns: the scalar loop body,
//   n += w_i;  diff = w_i·(f_i − c);  s1 += diff;  s2 += diff·diff.
// s1 as diff·1 + s1: a fused multiply-add of an exact product rounds as the addition does
// (the same bits), and it runs on the multiply ports, so that the two adder ports and the two
// multiply ports of a core (as on AMD Zen 4) each get three of the tap's six operations.
HWY_INLINE void HorizontalTap(VF wi, VF fi, VF c, VF& sn, VF& s1, VF& s2) {
  const VF diff = hn::Mul(wi, hn::Sub(fi, c));
  sn = hn::Add(sn, wi);
  s1 = hn::MulAdd(diff, hn::Set(DF(), 1.0f), s1);
  s2 = hn::Add(s2, hn::Mul(diff, diff));
}

}  // namespace

// The horizontal pass of one row for half-width r over the columns [lo, hi] (and the rest of
// their last vector that lies in the image): for column x, over [x − rx, x + rx] with
// rx = min(r, x, w − 1 − x), the count, Σ(f − c) and Σ(f − c)² about the reference c = the
// nearest valid pixel's depth if it lies in the segment, else 0 (horizontal_row in
// chebyshev.cpp). `near_dist`, `near_depth`: the row's nearest valid pixel per column and its
// distance, or null if the row has no background (the reference is then the pixel itself).
void HorizontalSpan(const float* HWY_RESTRICT depth, const float* HWY_RESTRICT weight,
                    const int* HWY_RESTRICT near_dist, const float* HWY_RESTRICT near_depth, int w,
                    int r, int lo, int hi, double* HWY_RESTRICT hn_out, double* HWY_RESTRICT hs1,
                    double* HWY_RESTRICT hs2, double* HWY_RESTRICT hc) {
  const DF df;
  const DI di;
  const int n = int(hn::Lanes(df));
  const VI vr = hn::Set(di, r), last = hn::Set(di, w - 1);
  auto reference = [&](int x0, VI& rx) {
    const VI x = hn::Iota(di, x0);
    rx = hn::Min(vr, hn::Min(x, hn::Sub(last, x)));
    if (!near_dist) return hn::LoadU(df, depth + x0);  // every pixel valid: its own depth
    const auto inside = hn::RebindMask(df, hn::Not(hn::Gt(hn::LoadU(di, near_dist + x0), rx)));
    return hn::IfThenElseZero(inside, hn::LoadU(df, near_depth + x0));
  };
  // Stored as doubles: the vertical pass reads every value 2·rv + 1 times and would convert
  // it each time (the conversions, not the sums, were its bottleneck); exact either way.
  const DD dd;
  const DFH dfh;
  const int nd = int(hn::Lanes(dd));
  auto store_one = [&](VF v, int count, double* HWY_RESTRICT out) {
    HWY_ALIGN float lanes[hn::MaxLanes(df)];
    hn::Store(v, df, lanes);
    for (int k = 0; k < count; k += nd) {
      const auto wide = hn::PromoteTo(dd, hn::Load(dfh, lanes + k));
      if (count - k >= nd) {
        hn::StoreU(wide, dd, out + k);
      } else {
        HWY_ALIGN double part[hn::MaxLanes(dd)];
        hn::Store(wide, dd, part);
        for (int i = 0; i < count - k; ++i) out[k + i] = part[i];
      }
    }
  };
  auto store = [&](int x0, VF c, VF sn, VF s1, VF s2) {
    const int count = std::min(n, w - x0);
    store_one(sn, count, hn_out + x0);
    store_one(s1, count, hs1 + x0);
    store_one(s2, count, hs2 + x0);
    store_one(c, count, hc + x0);
  };
  // Vectors whose every column has its full segment (rx = r): no masks; two at a time, so
  // that the three dependent sums of one vector do not wait on each other's latency alone.
  const int interior_end = w - r - n;  // last x0 whose vector is interior
  int x0 = lo;
  for (; x0 <= hi; x0 += n) {
    if (x0 >= r && x0 + n <= interior_end && x0 + n <= hi) {
      VI rx;
      const VF ca = reference(x0, rx), cb = reference(x0 + n, rx);
      VF na = hn::Zero(df), s1a = na, s2a = na, nb = na, s1b = na, s2b = na;
      const float* d = depth + x0;
      const float* m = weight + x0;
      for (int i = -r; i <= r; ++i) {
        HorizontalTap(hn::LoadU(df, m + i), hn::LoadU(df, d + i), ca, na, s1a, s2a);
        HorizontalTap(hn::LoadU(df, m + i + n), hn::LoadU(df, d + i + n), cb, nb, s1b, s2b);
      }
      store(x0, ca, na, s1a, s2a);
      store(x0 + n, cb, nb, s1b, s2b);
      x0 += n;
      continue;
    }
    VI rx;
    const VF c = reference(x0, rx);
    VF sn = hn::Zero(df), s1 = sn, s2 = sn;
    if (x0 >= r && x0 <= interior_end) {
      for (int i = -r; i <= r; ++i)
        HorizontalTap(hn::LoadU(df, weight + x0 + i), hn::LoadU(df, depth + x0 + i), c, sn, s1, s2);
    } else {
      // A border vector: lane x takes only the taps |i| ≤ rx(x) (none for x ≥ w).
      for (int i = -r; i <= r; ++i) {
        const auto take = hn::RebindMask(df, hn::Not(hn::Gt(hn::Set(di, i < 0 ? -i : i), rx)));
        if (hn::AllFalse(df, take)) continue;
        const VF wi = hn::IfThenElseZero(take, LoadInRow(df, weight, x0 + i, w));
        HorizontalTap(wi, LoadInRow(df, depth, x0 + i, w), c, sn, s1, s2);
      }
    }
    store(x0, c, sn, s1, s2);
  }
}

namespace {

// One row of the vertical pass's sum for a vector of receivers at depth d (vertical_row's loop
// body): the row's sums shifted from its reference c onto d, δ = c − d.
HWY_INLINE void VerticalTap(DD dd, const double* HWY_RESTRICT bn, const double* HWY_RESTRICT b1,
                            const double* HWY_RESTRICT b2, const double* HWY_RESTRICT bc,
                            std::size_t o, VD d, VD& sn, VD& s1, VD& s2) {
  const VD one = hn::Set(dd, 1.0);
  const VD nj = hn::LoadU(dd, bn + o);
  const VD a = hn::LoadU(dd, b1 + o);
  const VD delta = hn::Sub(hn::LoadU(dd, bc + o), d);
  const VD n_delta = hn::Mul(nj, delta);
  // x·1 + y and 2·a + y round exactly as x + y and (2·a) + y (the products are exact, and a
  // fused multiply-add rounds once): the same bits as the scalar code's additions, with the
  // tap's nine operations split 4 : 5 between the adder and the multiply ports (all nine
  // on the adders, the pass was bound by them).
  sn = hn::Add(sn, nj);
  s1 = hn::MulAdd(hn::Add(a, n_delta), one, s1);
  s2 = hn::MulAdd(
      hn::Add(hn::LoadU(dd, b2 + o), hn::Mul(delta, hn::MulAdd(hn::Set(dd, 2.0), a, n_delta))), one,
      s2);
}

// The moments of a vector of receivers from their window sums, and what the caller wants of
// them at the lanes `receiver`: n, λ, σ² (`moments`) or the visibility (`ao`).
HWY_INLINE void VerticalFinish(VD sn, VD s1, VD s2, hn::Mask<DIH> receiver, int count,
                               std::size_t row, int x0, const ChebyshevSettings& s, double eps,
                               float* HWY_RESTRICT moments, float* HWY_RESTRICT ao) {
  const DD dd;
  const DFH dfh;
  const DIH dih;
  const VD zero = hn::Zero(dd), one = hn::Set(dd, 1.0), two = hn::Set(dd, 2.0);
  const VD m1 = hn::Div(s1, sn), m2 = hn::Div(s2, sn);
  const VD spread = hn::Sub(m2, hn::Mul(m1, m1));
  // std::max(0.0, spread): 0 unless 0 < spread.
  const auto gap = hn::DemoteTo(dfh, hn::Neg(m1));
  const auto variance = hn::DemoteTo(dfh, hn::IfThenElseZero(hn::Gt(spread, zero), spread));
  if (moments) {
    HWY_ALIGN float count_lanes[hn::MaxLanes(dd)], gap_lanes[hn::MaxLanes(dd)],
        var_lanes[hn::MaxLanes(dd)];
    HWY_ALIGN std::int32_t take[hn::MaxLanes(dd)];
    hn::Store(hn::DemoteTo(dfh, sn), dfh, count_lanes);
    hn::Store(gap, dfh, gap_lanes);
    hn::Store(variance, dfh, var_lanes);
    hn::Store(hn::VecFromMask(dih, receiver), dih, take);
    for (int i = 0; i < count; ++i) {
      if (!take[i]) continue;
      float* p = moments + (row + std::size_t(x0 + i)) * 3;
      p[0] = count_lanes[i], p[1] = gap_lanes[i], p[2] = var_lanes[i];
    }
    return;
  }
  // chebyshev_visibility(gap, variance, s), lane by lane the same operations.
  const VD var0 = hn::PromoteTo(dd, variance);
  const VD var = hn::IfThenElseZero(hn::Gt(var0, zero), var0);  // std::max(0.0, variance)
  VD lambda = hn::PromoteTo(dd, gap);
  const VD tolerance = hn::Mul(hn::Set(dd, kChebyshevMeanTolerance),
                               hn::Sqrt(hn::Add(var, hn::Mul(lambda, lambda))));
  lambda = hn::IfThenZeroElse(hn::Le(hn::Abs(lambda), tolerance), lambda);
  const VD g =
      s.ignore_unoccluded ? hn::IfThenZeroElse(hn::Lt(lambda, zero), lambda) : hn::Abs(lambda);
  const auto occluded = hn::Gt(g, zero);
  const VD biased = hn::Add(var, hn::Set(dd, eps));
  const VD p = hn::Div(biased, hn::Add(biased, hn::Mul(g, g)));
  VD a;
  if (!s.range_check) {
    a = p;
  } else {
    const VD ratio = hn::Div(hn::Set(dd, double(s.radius)), g);
    const VD t = hn::IfThenElse(hn::Lt(ratio, one), ratio, one);  // std::min(1.0, ratio)
    const VD fade = hn::Mul(hn::Mul(t, t), hn::Sub(hn::Set(dd, 3.0), hn::Mul(two, t)));
    a = hn::Sub(one, hn::Mul(hn::Sub(one, p), fade));
  }
  // std::clamp(a, 0.0, 1.0)
  a = hn::IfThenElse(hn::Lt(a, zero), zero, hn::IfThenElse(hn::Lt(one, a), one, a));
  a = hn::IfThenElse(occluded, a, one);
  hn::BlendedStore(hn::DemoteTo(dfh, a), hn::RebindMask(dfh, receiver), dfh, ao + row + x0);
}

}  // namespace

// The vertical pass of receiver row y for the receivers of level `l` in the columns [xa, xb)
// (vertical_row in chebyshev.cpp): each row's sums (half-width rh, rows y − ry … y + ry with
// ry = min(rv, y, h − 1 − y)) shifted onto the receiver's depth d with δ = c − d,
//   Σ(f − d) = s1 + n·δ,  Σ(f − d)² = s2 + δ·(2·s1 + n·δ),
// summed in double; then m1, m2, λ = −m1 and σ² = max(0, m2 − m1²), rounded to float. Writes
// n, λ, σ² to `moments` (3 channels per pixel) if it is not null, else the visibility
// (chebyshev_visibility) to `ao`; only at the level's receivers. Row y′ of the horizontal
// sums is row slot[y′] of the buffers bn, b1, b2, bc. Vectors without a receiver
// are skipped; two vectors are summed together where both have one, so that the sums' add
// latencies overlap.
void VerticalSpan(const float* HWY_RESTRICT depth, const int* HWY_RESTRICT level,
                  const double* HWY_RESTRICT bn, const double* HWY_RESTRICT b1,
                  const double* HWY_RESTRICT b2, const double* HWY_RESTRICT bc,
                  const int* HWY_RESTRICT slot, int w, int h, int l, int rv, int y, int xa, int xb,
                  const ChebyshevSettings& s, double eps, float* HWY_RESTRICT moments,
                  float* HWY_RESTRICT ao) {
  const DD dd;
  const DFH dfh;
  const DIH dih;
  const int n = int(hn::Lanes(dd));
  const int ry = std::min({rv, y, h - 1 - y});
  const std::size_t row = std::size_t(y) * w;
  auto receivers = [&](int x0, int& count) {
    count = std::max(0, std::min(n, xb - x0));
    return hn::And(hn::Eq(hn::LoadU(dih, level + row + x0), hn::Set(dih, l)),
                   hn::FirstN(dih, std::size_t(count)));
  };
  for (int x0 = xa; x0 < xb; x0 += 2 * n) {
    int count_a, count_b;
    const auto rec_a = receivers(x0, count_a), rec_b = receivers(x0 + n, count_b);
    const bool any_a = !hn::AllFalse(dih, rec_a), any_b = !hn::AllFalse(dih, rec_b);
    if (any_a && any_b) {
      const VD da = hn::PromoteTo(dd, hn::LoadU(dfh, depth + row + x0));
      const VD db = hn::PromoteTo(dd, hn::LoadU(dfh, depth + row + x0 + n));
      VD sna = hn::Zero(dd), s1a = sna, s2a = sna, snb = sna, s1b = sna, s2b = sna;
      for (int j = -ry; j <= ry; ++j) {
        const std::size_t o = std::size_t(slot[y + j]) * w + x0;
        VerticalTap(dd, bn, b1, b2, bc, o, da, sna, s1a, s2a);
        VerticalTap(dd, bn, b1, b2, bc, o + n, db, snb, s1b, s2b);
      }
      VerticalFinish(sna, s1a, s2a, rec_a, count_a, row, x0, s, eps, moments, ao);
      VerticalFinish(snb, s1b, s2b, rec_b, count_b, row, x0 + n, s, eps, moments, ao);
      continue;
    }
    for (int half = 0; half < 2; ++half) {
      if (!(half == 0 ? any_a : any_b)) continue;
      const int xh = x0 + half * n;
      const VD d = hn::PromoteTo(dd, hn::LoadU(dfh, depth + row + xh));
      VD sn = hn::Zero(dd), s1 = sn, s2 = sn;
      for (int j = -ry; j <= ry; ++j)
        VerticalTap(dd, bn, b1, b2, bc, std::size_t(slot[y + j]) * w + xh, d, sn, s1, s2);
      VerticalFinish(sn, s1, s2, half == 0 ? rec_a : rec_b, half == 0 ? count_a : count_b, row, xh,
                     s, eps, moments, ao);
    }
  }
}

}  // namespace aolab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace aolab {

HWY_EXPORT(HorizontalSpan);
HWY_EXPORT(VerticalSpan);

// The vertical pass's tiles: up to 4 receiver rows × 128 columns, which read (4 + 2·rv) rows
// of 128 columns × 32 bytes, 280 KB at rv = 32: within a core's L2 (512 KB to 1 MB on
// current x86), where whole rows (2.6 MB at 1280 columns) are not. Bands of 4 rows (fewer for
// a level with few receiver rows, so that every thread has several): a band of 16 rows takes
// ~0.25 ms, long enough to leave one thread idle at the end of each of the frame's ~20
// vertical passes.
constexpr int kVerticalBandRows = 4;
constexpr int kVerticalTileColumns = 128;
// The horizontal pass's bands (parallel_for_rows's default).
constexpr int kHorizontalBandRows = 4;
// Elements past a span that a vector may read: two vectors of the widest target.
constexpr int kSpanPadding = 32;

// The threads of one frame, kept for all its levels: each level's two passes are phases
// that the same workers run (bands handed out from an atomic counter, as parallel_for_rows
// does), so that a frame of ~20 levels starts its threads once rather than 40 times (a
// thread start and join cost 25–80 µs here, several percent of a 2-thread frame).
class Team {
 public:
  explicit Team(int threads) {
    for (int t = 1; t < threads; ++t) workers_.emplace_back([this] { serve(); });
  }
  Team(const Team&) = delete;
  Team& operator=(const Team&) = delete;
  ~Team() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    start_.notify_all();
    for (std::thread& t : workers_) t.join();
  }

  // body(i0, i1) over the bands of `band` items of [0, n), on every thread; adds finished
  // items to progress->done; throws what a band threw, or Cancelled if progress->cancel was
  // set.
  void run(int n, int band, const std::function<void(int, int)>& body, Progress* progress) {
    if (n <= 0) return;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      body_ = &body, progress_ = progress, n_ = n, band_ = std::max(1, band);
      next_ = 0, busy_ = int(workers_.size()), error_ = nullptr, failed_ = false;
      ++generation_;
    }
    start_.notify_all();
    work();
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [this] { return busy_ == 0; });
    if (error_) std::rethrow_exception(error_);
    if (progress && progress->cancel.load()) throw Cancelled();
  }

 private:
  void work() {
    for (;;) {
      if (failed_.load(std::memory_order_relaxed)) return;
      if (progress_ && progress_->cancel.load(std::memory_order_relaxed)) return;
      const int i0 = next_.fetch_add(band_, std::memory_order_relaxed);
      if (i0 >= n_) return;
      const int i1 = std::min(n_, i0 + band_);
      try {
        (*body_)(i0, i1);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(mutex_);
        if (!error_) error_ = std::current_exception();
        failed_ = true;
        return;
      }
      if (progress_) progress_->done.fetch_add(i1 - i0, std::memory_order_relaxed);
    }
  }

  void serve() {
    std::uint64_t seen = 0;
    for (;;) {
      {
        std::unique_lock<std::mutex> lock(mutex_);
        start_.wait(lock, [&] { return stop_ || generation_ != seen; });
        if (stop_) return;
        seen = generation_;
      }
      work();
      {
        const std::lock_guard<std::mutex> lock(mutex_);
        --busy_;
      }
      done_.notify_one();
    }
  }

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable start_, done_;
  bool stop_ = false;
  std::uint64_t generation_ = 0;
  int busy_ = 0;
  const std::function<void(int, int)>* body_ = nullptr;
  Progress* progress_ = nullptr;
  int n_ = 0, band_ = 1;
  std::atomic<int> next_{0};
  std::atomic<bool> failed_{false};
  std::exception_ptr error_;
};

void chebyshev_simd(const chebyshev_detail::Plan& plan, const ChebyshevSettings& s, int threads,
                    Progress* progress, Image* moments, Image* ao) {
  const chebyshev_detail::Frame& f = plan.frame;
  const int w = f.w, h = f.h;
  const std::size_t pixels = std::size_t(w) * h;
  if (moments) {
    // Pixels without a window (half-width 0): the window is the pixel itself.
    for (std::size_t i = 0; i < pixels; ++i)
      if (f.weight[i] != 0.0f && f.level[i] < 0) moments->data()[i * 3] = 1.0f;
  }
  if (plan.levels.empty()) return;

  // Rows holding background: only there does a column's reference need the nearest valid
  // pixel (elsewhere it is the pixel itself), found per row as the scalar pass does.
  std::vector<char> has_background(h);
  parallel_for_rows(h, threads, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      const float* m = f.weight.data() + std::size_t(y) * w;
      has_background[y] = std::find(m, m + w, 0.0f) != m + w;
    }
  });

  // The horizontal sums of one level at a time, its pass rows packed (row y in slot[y]): the
  // memory a frame touches, and so its page faults, stay a fraction of 32 bytes per pixel.
  // Left uninitialised: every value the vertical pass stores was written by the horizontal
  // pass (lanes past a span read whatever is there and are never stored).
  std::size_t slots = 0;
  for (const auto& r : plan.rows) slots = std::max(slots, r.pass_rows.size());
  const std::size_t buffer = slots * w + 2 * kSpanPadding;
  chebyshev_detail::FrameVector<double> bn(buffer), b1(buffer), b2(buffer), bc(buffer);
  std::vector<int> slot(h, 0);
  Team team(threads);
  const double radius = s.radius;
  const double eps = double(s.variance_bias) * radius * radius;  // ε = b·R² (§III-A)
  for (int l = 0; l < int(plan.levels.size()); ++l) {
    const chebyshev_detail::Level lv = plan.levels[l];
    const chebyshev_detail::LevelRows& rows = plan.rows[l];
    for (std::size_t i = 0; i < rows.pass_rows.size(); ++i) slot[rows.pass_rows[i]] = int(i);
    team.run(
        int(rows.pass_rows.size()), kHorizontalBandRows,
        [&](int i0, int i1) {
          std::vector<int> left(w), right(w), near_dist(w + kSpanPadding);
          std::vector<float> near_depth(w + kSpanPadding);
          for (int i = i0; i < i1; ++i) {
            const int y = rows.pass_rows[i];
            const std::size_t o = std::size_t(y) * w, ob = std::size_t(i) * w;
            const float* d = f.depth.data() + o;
            if (has_background[y]) {
              // The nearest valid pixel of each column (left on ties) and its distance (w if
              // the row has none), as horizontal_row finds them.
              const float* m = f.weight.data() + o;
              for (int x = 0, last = -1; x < w; ++x) left[x] = last = m[x] != 0.0f ? x : last;
              for (int x = w - 1, last = -1; x >= 0; --x) right[x] = last = m[x] != 0.0f ? x : last;
              for (int x = 0; x < w; ++x) {
                const int dl = left[x] >= 0 ? x - left[x] : w;
                const int dr = right[x] >= 0 ? right[x] - x : w;
                near_dist[x] = std::min(dl, dr);
                near_depth[x] = near_dist[x] < w ? d[dl <= dr ? left[x] : right[x]] : 0.0f;
              }
            }
            HWY_DYNAMIC_DISPATCH(HorizontalSpan)
            (d, f.weight.data() + o, has_background[y] ? near_dist.data() : nullptr,
             near_depth.data(), w, lv.rh, rows.need_lo[y], rows.need_hi[y], bn.data() + ob,
             b1.data() + ob, b2.data() + ob, bc.data() + ob);
          }
        },
        progress);
    // Receiver rows in bands, each band column tile by column tile, so that the rows a tile
    // reads (its band ± rv rows of four doubles per pixel) stay in the core's L2.
    team.run(
        int(rows.receiver_rows.size()),
        std::clamp(int(rows.receiver_rows.size()) / (4 * threads), 1, kVerticalBandRows),
        [&](int i0, int i1) {
          for (int x0 = 0; x0 < w; x0 += kVerticalTileColumns) {
            const int x1 = std::min(w, x0 + kVerticalTileColumns);
            for (int i = i0; i < i1; ++i) {
              const int y = rows.receiver_rows[i];
              const int xa = std::max(x0, rows.span_lo[y]), xb = std::min(x1, rows.span_hi[y] + 1);
              if (xa >= xb) continue;
              HWY_DYNAMIC_DISPATCH(VerticalSpan)
              (f.depth.data(), f.level.data(), bn.data(), b1.data(), b2.data(), bc.data(),
               slot.data(), w, h, l, lv.rv, y, xa, xb, s, eps, moments ? moments->data() : nullptr,
               ao ? ao->data() : nullptr);
            }
          }
        },
        progress);
  }
}

}  // namespace aolab
#endif  // HWY_ONCE
