// LSAO's SIMD kernel: the gather (§5.1) on Lanes consecutive pixels of a row at once, compiled
// by Highway for every target and dispatched at run time. The scalar code of lsao.cpp is the
// oracle it is tested against (docs/methods/lsao.md, "SIMD kernel").
//
// The scalar gather scatters: every sample is offered to the pixels of its stencil, one pixel
// at a time. Here the gather reads instead: per band of rows and per pair of opposite
// directions ("axis"), the samples are first written into a dense map of texels — the
// sample's depth and its coverage-weighted pair value, at the texel it was evaluated at —
// and every pixel then walks the stencil of texel offsets nearest first, taking the first
// sample that passes the tests. One offset is then one contiguous load for Lanes pixels, with
// no gather and no per-pixel branch; a vector stops when all of its pixels have their sample.
// The stencil is sorted by distance and, for equal distances, by the samples' order in the
// buffer (line, then position along it), which is the scalar code's tie rule, so both pick the
// same sample; the values differ only by float rounding of the weighted sums.
//
// Aligned direction sets (§5.2) with sampling = snap only, where every sample is a texel centre
// and the lines are lines of texel centres: an interpolated sample sits between texels and has
// no place in the map, and the samples of a uniform set, snapped up to half a texel off lines
// D_L apart, are not ordered across by their lines, so the stencil's order is not the tie
// rule; both run the scalar gather.
// The kernel evaluates the scalar code's expressions in its order with its IEEE operations
// (division and square root are exact in both), so GCC must not fuse a multiply and an add
// (-ffp-contract=fast is its default; the scalar code, built for baseline x86-64, has no FMA):
// the sweep then gives the scalar code's bits.
#pragma GCC optimize("fp-contract=off")
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/methods/lsao/lsao_simd.cpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/base/check.h"
#include "core/base/parallel.h"
#include "core/base/simd-inl.h"
#include "core/methods/lsao/lsao.h"
#include "core/methods/lsao/lsao_shared.h"

#ifndef AOLAB_LSAO_SIMD_ONCE_
#define AOLAB_LSAO_SIMD_ONCE_
namespace aolab::lsao_simd {

// One texel offset of an axis's stencil.
struct Offset {
  int dx, dy;
};

// A pair of opposite directions sharing their samples, as the gather sees it.
struct Axis {
  int lines = 0;                           // index into plan.lines
  int k[2] = {-1, -1};                     // its directions (k[1] = −1 if only one)
  float pair_weight = 0;                   // Σ w_k over them
  std::size_t first_run = 0, end_run = 0;  // its runs in sweep.texel_runs
  std::vector<Offset> stencil;             // nearest first; equal distances in buffer order
};

// Rows per band: a band's maps (rows + 2·reach, padded width) and its four accumulators stay
// within a core's L2 (~0.4 MiB at 1280 columns).
constexpr int kBandRows = 16;

// What every band reads.
struct Inputs {
  const LsaoPlan* plan;
  const LsaoSweep* sweep;
  std::vector<Axis> axes;
  const float* depth;    // W·H, background as NaN
  const float* normals;  // prepared, 3 per pixel; only with normal_aware
  bool normal_aware;
  float tolerance;
  int width, height;
  int reach;       // the largest stencil's |dy| and |dx|
  int pad_left;    // map columns left of x = 0
  int map_stride;  // floats per map row
  int map_rows;    // kBandRows + 2·reach
};

// Per worker: the maps of one axis over one band (and the normals there), and the band's
// coverage-weighted sums over the axes done so far.
struct Scratch {
  std::vector<float> depth, pair, nx, ny, nz;
  std::vector<float> sum, weight, sum_any, weight_any;
  explicit Scratch(const Inputs& in) {
    const std::size_t map = std::size_t(in.map_rows) * std::size_t(in.map_stride);
    depth.assign(map, std::numeric_limits<float>::quiet_NaN()), pair.assign(map, 0.0f);
    if (in.normal_aware) nx.assign(map, 0.0f), ny.assign(map, 0.0f), nz.assign(map, 0.0f);
    const std::size_t acc = std::size_t(kBandRows) * std::size_t(in.map_stride);
    for (auto* v : {&sum, &weight, &sum_any, &weight_any}) v->assign(acc, 0.0f);
  }
};

// ---- The sweep ----

// What every batch of lines reads.
struct SweepInputs {
  const LsaoPlan* plan;
  const LsaoSettings* s;
  const float* depth;    // W·H, background as NaN
  const float* normals;  // prepared, 3 per pixel; only for tangent strategies 1 and 2
  float inv_r;           // 1/r = 1/(C R²)
  std::vector<std::vector<int>> directions_of;  // per plan.lines entry: the directions using it
  float* buffer;                                // the sweep's records
  bool texel_runs;         // also the records of the SIMD gather (LsaoTexelRun)
  LsaoRecordArena* arena;  // where they go, with texel_runs
};

// Per worker: the samples of a batch's lines, transposed (row r of lane l at r·N + l), each
// lane's stack links the same way, and the values before they go to the records.
struct SweepScratch {
  std::vector<LsaoSample> samples;  // one line, line order (interpolated sampling)
  std::vector<float> x, y, d, value, value2;
  std::vector<std::int32_t> link;
  std::vector<std::uint32_t> cursor;
};

}  // namespace aolab::lsao_simd
#endif  // AOLAB_LSAO_SIMD_ONCE_

HWY_BEFORE_NAMESPACE();
namespace aolab::HWY_NAMESPACE {
namespace {
using lsao_simd::Axis;
using lsao_simd::Inputs;
using lsao_simd::Scratch;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// floor for |x| < 2^62 (the scalar code's floor_ll).
inline long long FloorLL(double x) {
  const long long t = (long long)x;
  return t - (double(t) > x ? 1 : 0);
}

// The samples of one axis whose texel lies in image rows [row_lo, row_hi), written into the
// maps at their texel: depth, and Σ w_k O_k of the axis's directions. The runs' records are
// read in buffer order and a texel keeps its first, as the scalar code's strict "nearer" keeps
// the first of equally near samples.
void FillMaps(const Inputs& in, const Axis& axis, int row_lo, int row_hi, int map_row0,
              Scratch& s) {
  // Empty texels: NaN (their pair is never read). Clearing the whole map measured faster than
  // keeping a list of the texels written and clearing those.
  std::fill(s.depth.begin(), s.depth.end(), kNaN);
  const std::vector<LsaoTexelRun>& runs = in.sweep->texel_runs;
  const int b0 = row_lo / kLsaoRecordRows, b1 = (row_hi - 1) / kLsaoRecordRows;
  const std::ptrdiff_t origin = std::ptrdiff_t(map_row0 - row_lo) * in.map_stride + in.pad_left;
  for (std::size_t r = axis.first_run; r < axis.end_run; ++r) {
    const LsaoTexelRun& run = runs[r];
    const LsaoTexelRecord* record = run.records + run.bucket_start[std::size_t(b0)];
    const LsaoTexelRecord* end = run.records + run.bucket_start[std::size_t(b1) + 1];
    for (; record < end; ++record) {
      const int y = record->y;
      if (y < row_lo || y >= row_hi) continue;
      const std::size_t m = std::size_t(origin + std::ptrdiff_t(y) * in.map_stride + record->x);
      if (s.depth[m] == s.depth[m]) continue;  // the texel keeps its first sample
      s.depth[m] = record->depth;
      s.pair[m] = record->pair;
    }
  }
}

// The prepared normals of image rows [row_lo, row_hi) as three padded planes.
void FillNormals(const Inputs& in, int row_lo, int row_hi, int map_row0, Scratch& s) {
  for (int y = row_lo; y < row_hi; ++y) {
    const std::size_t m =
        std::size_t(y - row_lo + map_row0) * std::size_t(in.map_stride) + std::size_t(in.pad_left);
    const float* n = in.normals + 3 * std::size_t(y) * std::size_t(in.width);
    for (int x = 0; x < in.width; ++x) {
      s.nx[m + x] = n[3 * x], s.ny[m + x] = n[3 * x + 1], s.nz[m + x] = n[3 * x + 2];
    }
  }
}

// One band: per axis, the maps, then every pixel's nearest passing sample (and nearest sample
// regardless); then A = 1 − Σ w O / Σ w.
void GatherBand(const Inputs& in, int band, Scratch& s, float* out_image) {
  const DF df;
  const int y0 = band * lsao_simd::kBandRows;
  const int y1 = std::min(in.height, y0 + lsao_simd::kBandRows);
  const int row_lo = std::max(0, y0 - in.reach), row_hi = std::min(in.height, y1 + in.reach);
  const int map_row0 = row_lo - (y0 - in.reach);  // map row of image row row_lo
  const std::size_t ms = std::size_t(in.map_stride);
  for (auto* v : {&s.sum, &s.weight, &s.sum_any, &s.weight_any})
    std::fill(v->begin(), v->end(), 0.0f);
  if (in.normal_aware) {
    // Rows outside the image are never read: their depth map stays NaN.
    FillNormals(in, row_lo, row_hi, map_row0, s);
  }
  const VF tolerance = hn::Set(df, in.tolerance);
  const VF normal_cos = hn::Set(df, kLsaoGatherNormalCos);
  for (const Axis& axis : in.axes) {
    FillMaps(in, axis, row_lo, row_hi, map_row0, s);
    const VF pair_weight = hn::Set(df, axis.pair_weight);
    for (int y = y0; y < y1; ++y) {
      const float* depth_row = in.depth + std::size_t(y) * std::size_t(in.width);
      // Map index of (x = 0, y): y is map row y − y0 + reach.
      const std::size_t centre = std::size_t(y - y0 + in.reach) * ms + std::size_t(in.pad_left);
      const std::size_t acc_row = std::size_t(y - y0) * ms;
      ForEachRowVector(df, in.width, [&](int x0, int count) {
        const VF dp = LoadRowPart(df, depth_row + x0, count);
        const MF geometry = hn::Eq(dp, dp);
        const VF limit = hn::Mul(tolerance, dp);
        VF npx, npy, npz;
        if (in.normal_aware) {
          const std::size_t c = centre + std::size_t(x0);
          npx = hn::LoadU(df, s.nx.data() + c), npy = hn::LoadU(df, s.ny.data() + c);
          npz = hn::LoadU(df, s.nz.data() + c);
        }
        // Background pixels are done before they start (they stay 1).
        MF found = hn::Not(geometry), found_any = found;
        VF pair = hn::Zero(df), pair_any = hn::Zero(df);
        for (const lsao_simd::Offset& o : axis.stencil) {
          const std::size_t m = std::size_t(std::ptrdiff_t(centre) + std::ptrdiff_t(x0) +
                                            std::ptrdiff_t(o.dy) * std::ptrdiff_t(ms) + o.dx);
          const VF dq = hn::LoadU(df, s.depth.data() + m);
          const MF sample = hn::Eq(dq, dq);
          const MF first_any = hn::AndNot(found_any, sample);
          MF pass = hn::And(hn::AndNot(found, sample), hn::Le(hn::Abs(hn::Sub(dq, dp)), limit));
          if (in.normal_aware && !hn::AllFalse(df, pass)) {
            const VF dot = hn::Add(hn::Add(hn::Mul(npx, hn::LoadU(df, s.nx.data() + m)),
                                           hn::Mul(npy, hn::LoadU(df, s.ny.data() + m))),
                                   hn::Mul(npz, hn::LoadU(df, s.nz.data() + m)));
            pass = hn::And(pass, hn::Ge(dot, normal_cos));
          }
          if (!hn::AllFalse(df, hn::Or(first_any, pass))) {
            const VF value = hn::LoadU(df, s.pair.data() + m);
            pair_any = hn::IfThenElse(first_any, value, pair_any);
            pair = hn::IfThenElse(pass, value, pair);
            found_any = hn::Or(found_any, first_any);
            found = hn::Or(found, pass);
            // A passing sample is also the nearest of all or nearer ones were taken before.
            if (hn::AllTrue(df, found)) break;
          }
        }
        const MF tested = hn::And(found, geometry), any = hn::And(found_any, geometry);
        float* sum = s.sum.data() + acc_row + x0;
        float* weight = s.weight.data() + acc_row + x0;
        float* sum_any = s.sum_any.data() + acc_row + x0;
        float* weight_any = s.weight_any.data() + acc_row + x0;
        hn::StoreU(hn::Add(hn::LoadU(df, sum), hn::IfThenElseZero(tested, pair)), df, sum);
        hn::StoreU(hn::Add(hn::LoadU(df, weight), hn::IfThenElseZero(tested, pair_weight)), df,
                   weight);
        hn::StoreU(hn::Add(hn::LoadU(df, sum_any), hn::IfThenElseZero(any, pair_any)), df, sum_any);
        hn::StoreU(hn::Add(hn::LoadU(df, weight_any), hn::IfThenElseZero(any, pair_weight)), df,
                   weight_any);
      });
    }
  }
  // A = 1 − Σ w_k O_k / Σ w_k over the directions taken; with none passing the tests, the
  // nearest values regardless; with none at all, 1.
  const VF one = hn::Set(df, 1.0f), zero = hn::Zero(df);
  for (int y = y0; y < y1; ++y) {
    const std::size_t acc_row = std::size_t(y - y0) * ms;
    float* out = out_image + std::size_t(y) * std::size_t(in.width);
    ForEachRowVector(df, in.width, [&](int x0, int count) {
      const std::size_t a = acc_row + std::size_t(x0);
      const VF weight = hn::LoadU(df, s.weight.data() + a);
      const MF tested = hn::Gt(weight, zero);
      const VF total = hn::IfThenElse(tested, weight, hn::LoadU(df, s.weight_any.data() + a));
      const VF sum = hn::IfThenElse(tested, hn::LoadU(df, s.sum.data() + a),
                                    hn::LoadU(df, s.sum_any.data() + a));
      const MF some = hn::Gt(total, zero);
      const VF ao = hn::Sub(one, hn::Div(sum, hn::IfThenElse(some, total, one)));
      const VF result = hn::IfThenElse(some, hn::Min(hn::Max(ao, zero), one), one);
      StoreRowPart(df, result, count, out + x0);
    });
  }
}

// ---- The sweep: Algorithm 1 on Lanes lines of one direction at once ----

using lsao_simd::SweepInputs;
using lsao_simd::SweepScratch;

// The slice of a direction (lsao.cpp, make_slice): per direction D, E and Δo·D per pixel; per
// lane (line) c_L and κ.
struct SliceV {
  VF dx, dy, ex, ey, along_fx, along_fy, cx, cy;
  VF c_line, kappa;
};

// The receiver p of each lane: position, o_p·D and û.
struct ReceiverV {
  VF x, y, d, o_along, ua, uz;
};

// evaluate(): eq. 1's terms for occluder q seen from p.
struct EvalV {
  VF crit, sin_h, rho, rest;
  MF zero;
};

HWY_INLINE EvalV Evaluate(DF df, const SliceV& s, const ReceiverV& p, VF qx, VF qy, VF qd,
                          VF sin_t_hull, VF inv_r, LsaoFalloff falloff) {
  const VF dx = hn::Sub(qx, p.x), dy = hn::Sub(qy, p.y), dd = hn::Sub(qd, p.d);
  const VF ha = hn::Add(hn::Mul(qd, hn::Add(hn::Mul(dx, s.along_fx), hn::Mul(dy, s.along_fy))),
                        hn::Mul(p.o_along, dd));
  const VF hz = hn::Neg(hn::Mul(s.kappa, dd));
  const VF len2 = hn::Add(hn::Mul(ha, ha), hn::Mul(hz, hz));
  EvalV e;
  e.zero = hn::Eq(len2, hn::Zero(df));
  const VF one = hn::Set(df, 1.0f);
  const VF safe = hn::IfThenElse(e.zero, one, len2);
  e.sin_h = hn::IfThenZeroElse(
      e.zero, hn::Div(hn::Add(hn::Mul(ha, p.ua), hn::Mul(hz, p.uz)), hn::Sqrt(safe)));
  // lsao_falloff(d²/r): an overflowing q2 gives ρ = 0.
  const VF q2 = hn::Mul(len2, inv_r);
  const MF finite = hn::Lt(q2, hn::Set(df, std::numeric_limits<float>::infinity()));
  VF rho, rest;
  if (falloff == LsaoFalloff::Cutoff) {
    const MF within = hn::Le(hn::Mul(q2, hn::Set(df, kLsaoFalloffOffset)), one);
    rho = hn::IfThenElseZero(within, one);
    rest = hn::IfThenZeroElse(within, one);
  } else {
    rho = hn::Div(one, hn::Add(one, q2));
    rest = hn::Mul(q2, rho);
    if (falloff == LsaoFalloff::Eq3) {
      const VF c = hn::Set(df, kLsaoFalloffOffset), c1 = hn::Set(df, 1.0f + kLsaoFalloffOffset);
      rho = hn::Max(hn::Zero(df), hn::Sub(hn::Mul(c1, rho), c));
      rest = hn::Min(one, hn::Mul(c1, rest));
    }
  }
  const MF weighed = hn::AndNot(e.zero, finite);
  e.rho = hn::IfThenElseZero(weighed, rho);
  e.rest = hn::IfThenElse(weighed, rest, one);
  e.crit = hn::Mul(hn::Max(hn::Zero(df), hn::Sub(e.sin_h, sin_t_hull)), e.rho);
  return e;
}

HWY_INLINE EvalV Select(MF m, const EvalV& a, const EvalV& b) {
  return {hn::IfThenElse(m, a.crit, b.crit), hn::IfThenElse(m, a.sin_h, b.sin_h),
          hn::IfThenElse(m, a.rho, b.rho), hn::IfThenElse(m, a.rest, b.rest),
          hn::Or(hn::And(m, a.zero), hn::AndNot(m, b.zero))};
}

// A batch's lines laid out for the sweep: their samples transposed (row r of lane l at r·N + l)
// and aligned at their ends: lane l's sample i is on row steps − n_l + i, the rows before it
// are background. The forward sweep walks the rows up, the opposite one down: both read the
// same rows.
struct BatchLayout {
  const LsaoLines* lines;
  int li, l0, lanes;  // plan.lines[li], lines [l0, l0 + lanes)
  int N;              // Lanes
  int steps;          // rows: the longest line's samples

  HWY_INLINE const LsaoLine& Line(int lane) const { return lines->lines[std::size_t(l0 + lane)]; }
  // The row of lane `lane`'s sample i.
  HWY_INLINE std::size_t RowOf(int lane, int i) const {
    return std::size_t(steps - Line(lane).count + i);
  }
};

// lsao_line_samples with snapping, the n samples of `line` into x, y, d (N floats apart): the
// containing texel's centre and depth. Lanes of doubles along the line: lsao_sample_position's
// operations (a multiply, then an add) and an exact floor, so the same texels; the depths
// gathered.
HWY_INLINE void SnapLineSamples(const SweepInputs& in, const SweepDirection& dir,
                                const LsaoLine& line, int n, int N, float* x, float* y, float* d) {
  const DD dd;
  const DFH dh;
  const DIH dih;
  const int m = int(hn::Lanes(dd));
  HWY_ALIGN float bx[hn::MaxLanes(dd)], by[hn::MaxLanes(dd)], bd[hn::MaxLanes(dd)];
  const auto ox = hn::Set(dd, line.origin_x), oy = hn::Set(dd, line.origin_y);
  const auto sx = hn::Set(dd, dir.step_x), sy = hn::Set(dd, dir.step_y);
  const auto width = hn::Set(dd, double(in.plan->width));
  const auto half = hn::Set(dh, 0.5f);
  for (int i0 = 0; i0 < n; i0 += m) {
    const int count = std::min(m, n - i0);
    const auto j = hn::Iota(dd, double(line.first + i0));
    const auto tx = hn::Floor(hn::Add(ox, hn::Mul(j, sx)));
    const auto ty = hn::Floor(hn::Add(oy, hn::Mul(j, sy)));
    const auto valid = hn::FirstN(dih, std::size_t(count));
    const auto index =
        hn::IfThenElseZero(valid, hn::DemoteTo(dih, hn::Add(hn::Mul(ty, width), tx)));
    hn::Store(hn::Add(hn::DemoteTo(dh, tx), half), dh, bx);
    hn::Store(hn::Add(hn::DemoteTo(dh, ty), half), dh, by);
    hn::Store(hn::GatherIndex(dh, in.depth, index), dh, bd);
    for (int k = 0; k < count; ++k) {
      const std::size_t at = std::size_t(i0 + k) * std::size_t(N);
      x[at] = bx[k], y[at] = by[k], d[at] = bd[k];
    }
  }
}

// Lines [l0, l1) of plan.lines[li] sampled into the scratch, laid out as BatchLayout says (and
// their depths into the buffer's records, if any).
HWY_INLINE BatchLayout LayOutSamples(const SweepInputs& in, int li, int l0, int l1,
                                     SweepScratch& sc) {
  const LsaoPlan& plan = *in.plan;
  BatchLayout b{&plan.lines[std::size_t(li)], li, l0, l1 - l0, int(hn::Lanes(DF())), 0};
  const int N = b.N;
  const std::size_t stride = std::size_t(plan.stride[std::size_t(li)]);
  const LsaoSampling sampling = LsaoSampling(in.s->sampling);
  for (int lane = 0; lane < b.lanes; ++lane) b.steps = std::max(b.steps, b.Line(lane).count);
  const std::size_t size = std::size_t(b.steps) * std::size_t(N);
  for (auto* v : {&sc.x, &sc.y, &sc.d, &sc.value, &sc.value2})
    if (v->size() < size) v->resize(size);
  if (sc.link.size() < size) sc.link.resize(size);
  for (int lane = 0; lane < N; ++lane) {
    const int n = lane < b.lanes ? b.Line(lane).count : 0;
    for (int r = 0; r < b.steps - n; ++r) {
      const std::size_t at = std::size_t(r) * std::size_t(N) + std::size_t(lane);
      sc.x[at] = 0.5f, sc.y[at] = 0.5f, sc.d[at] = kNaN;
    }
    if (n == 0) continue;
    const LsaoLine& line = b.Line(lane);
    float* records = in.buffer ? in.buffer + plan.depth_index(li, line.offset) : nullptr;
    float* x = sc.x.data() + b.RowOf(lane, 0) * std::size_t(N) + std::size_t(lane);
    float* y = sc.y.data() + (x - sc.x.data());
    float* d = sc.d.data() + (x - sc.x.data());
    if (sampling == LsaoSampling::Snap) {
      SnapLineSamples(in, plan.directions[std::size_t(b.lines->direction)], line, n, N, x, y, d);
    } else {
      lsao_line_samples(plan, in.depth, sampling, li, l0 + lane, sc.samples);
      for (int i = 0; i < n; ++i) {
        const LsaoSample& q = sc.samples[std::size_t(i)];
        x[std::size_t(i) * std::size_t(N)] = q.x, y[std::size_t(i) * std::size_t(N)] = q.y;
        d[std::size_t(i) * std::size_t(N)] = q.depth;
      }
    }
    if (records)
      for (int i = 0; i < n; ++i)
        records[std::size_t(i) * stride] = d[std::size_t(i) * std::size_t(N)];
  }
  return b;
}

// make_slice of direction `dir`, as lsao.cpp computes it, for the batch's lines (a lane past
// the batch repeats its last line).
HWY_INLINE SliceV MakeSlice(DF df, const CameraIntrinsics& cam, const BatchLayout& b,
                            const SweepDirection& dir) {
  const double ox = dir.step_x / cam.fx, oy = -dir.step_y / cam.fy;
  const double len = std::hypot(ox, oy);
  const float sdx = float(ox / len), sdy = float(oy / len), sex = -sdy, sey = sdx;
  SliceV s;
  s.dx = hn::Set(df, sdx), s.dy = hn::Set(df, sdy), s.ex = hn::Set(df, sex);
  s.ey = hn::Set(df, sey);
  s.along_fx = hn::Set(df, float(double(sdx) / cam.fx));
  s.along_fy = hn::Set(df, float(-double(sdy) / cam.fy));
  s.cx = hn::Set(df, cam.cx), s.cy = hn::Set(df, cam.cy);
  HWY_ALIGN float c_line[hn::MaxLanes(df)], kappa[hn::MaxLanes(df)];
  for (int lane = 0; lane < b.N; ++lane) {
    const LsaoLine& line = b.Line(std::min(lane, b.lanes - 1));
    const double c =
        (line.origin_x - cam.cx) / cam.fx * sex - (line.origin_y - cam.cy) / cam.fy * sey;
    c_line[lane] = float(c), kappa[lane] = float(std::sqrt(1.0 + c * c));
  }
  s.c_line = hn::Load(df, c_line), s.kappa = hn::Load(df, kappa);
  return s;
}

// The receiver p of each lane at row offset t: its sample, o_p·D and û.
HWY_INLINE ReceiverV LoadReceiver(DF df, const SliceV& s, const SweepScratch& sc, std::size_t t) {
  ReceiverV p;
  p.x = hn::LoadU(df, sc.x.data() + t), p.y = hn::LoadU(df, sc.y.data() + t);
  p.d = hn::LoadU(df, sc.d.data() + t);
  p.o_along =
      hn::Add(hn::Mul(hn::Sub(p.x, s.cx), s.along_fx), hn::Mul(hn::Sub(p.y, s.cy), s.along_fy));
  const VF ua = hn::Neg(p.o_along);
  const VF norm = hn::Sqrt(hn::Add(hn::Mul(ua, ua), hn::Mul(s.kappa, s.kappa)));
  p.ua = hn::Div(ua, norm), p.uz = hn::Div(s.kappa, norm);
  return p;
}

// real_tangent_sin at each lane's sample texel (geometry lanes; fixed_v elsewhere): sin t of
// the obscurance's tangent.
HWY_INLINE VF RealTangentSin(DF df, const SweepInputs& in, const SliceV& s, const ReceiverV& p,
                             MI geometry_i, VF fixed_v) {
  const DI di;
  const VI texel =
      hn::Add(hn::Mul(hn::ConvertTo(di, p.y), hn::Set(di, in.plan->width)), hn::ConvertTo(di, p.x));
  const VI at = hn::IfThenElseZero(geometry_i, hn::Mul(texel, hn::Set(di, 3)));
  const VF n0 = hn::GatherIndex(df, in.normals, at);
  const VF n1 = hn::GatherIndex(df, in.normals + 1, at);
  const VF n2 = hn::GatherIndex(df, in.normals + 2, at);
  const VF na = hn::Add(hn::Mul(n0, s.dx), hn::Mul(n1, s.dy));
  const VF nz = hn::Div(
      hn::Sub(n2, hn::Mul(s.c_line, hn::Add(hn::Mul(n0, s.ex), hn::Mul(n1, s.ey)))), s.kappa);
  const VF ne = hn::Add(hn::Mul(hn::Neg(na), p.uz), hn::Mul(nz, p.ua));
  const VF nu = hn::Max(hn::Zero(df), hn::Add(hn::Mul(na, p.ua), hn::Mul(nz, p.uz)));
  const VF den = hn::Sqrt(hn::Add(hn::Mul(ne, ne), hn::Mul(nu, nu)));
  const MF open = hn::Gt(den, hn::Zero(df));
  return hn::IfThenElse(open, hn::Div(hn::Neg(ne), hn::IfThenElse(open, den, hn::Set(df, 1.0f))),
                        fixed_v);
}

// Every lane's stack, as a linked list through the rows: an entry is the sample of the row where
// it was pushed (its position is already in x, y, d), and link[row] names the row of the entry
// below it. A push is then a contiguous store of the links, not a scatter of positions;
// reaching an entry under the top takes one more gather.
struct StackV {
  VI sp;          // stack sizes
  VI top_row;     // row of the top entry
  VF tx, ty, td;  // its position
};

// The rows of the samples, and the links between the stacks' entries, for the gathers.
struct Rows {
  const float *x, *y, *d;
  const std::int32_t* link;
  VI n_v, lane_index;

  HWY_INLINE VI At(VI row) const { return hn::Add(hn::Mul(row, n_v), lane_index); }
  // The row under `row` where m, else 0.
  HWY_INLINE VI Below(MI m, VI row) const {
    return hn::IfThenElseZero(m, hn::GatherIndex(DI(), link, At(hn::IfThenElseZero(m, row))));
  }
};

// What every evaluation of one step shares: evaluate() from p against the slice.
struct StepV {
  const SliceV& s;
  const ReceiverV& p;
  VF sin_t_hull, inv_r;
  LsaoFalloff falloff;

  HWY_INLINE EvalV Eval(DF df, VF qx, VF qy, VF qd) const {
    return Evaluate(df, s, p, qx, qy, qd, sin_t_hull, inv_r, falloff);
  }
};

// A top at p's own position is no occluder: p replaces it. Pops such tops (on the geometry
// lanes) and returns the evaluation of the top left.
HWY_INLINE EvalV DropCoincidentTops(DF df, const StepV& e, const Rows& rows, MI geometry_i,
                                    StackV& st) {
  const DI di;
  EvalV top = e.Eval(df, st.tx, st.ty, st.td);
  for (;;) {
    const MI nonempty = hn::And(geometry_i, hn::Gt(st.sp, hn::Zero(di)));
    const MI zero = hn::And(nonempty, hn::RebindMask(di, top.zero));
    if (hn::AllFalse(di, zero)) break;
    st.sp = hn::IfThenElse(zero, hn::Sub(st.sp, hn::Set(di, 1)), st.sp);
    st.top_row = hn::IfThenElse(zero, rows.Below(zero, st.top_row), st.top_row);
    const VI at = rows.At(st.top_row);
    const MF z = hn::RebindMask(df, zero);
    st.tx = hn::IfThenElse(z, hn::GatherIndex(df, rows.x, at), st.tx);
    st.ty = hn::IfThenElse(z, hn::GatherIndex(df, rows.y, at), st.ty);
    st.td = hn::IfThenElse(z, hn::GatherIndex(df, rows.d, at), st.td);
    top = Select(z, e.Eval(df, st.tx, st.ty, st.td), top);
  }
  return top;
}

// Algorithm 1, lines 12–18, on the lanes `has` (a stack): pop while the top casts less than
// the point below it and lies below it.
HWY_INLINE void PopHull(DF df, const StepV& e, const Rows& rows, MI has, StackV& st, EvalV& top) {
  const DI di;
  for (;;) {
    const MI two = hn::And(has, hn::Gt(st.sp, hn::Set(di, 1)));
    if (hn::AllFalse(di, two)) break;
    const VI below_row = rows.Below(two, st.top_row);
    const VI at = rows.At(below_row);
    const VF bx = hn::GatherIndex(df, rows.x, at);
    const VF by = hn::GatherIndex(df, rows.y, at);
    const VF bd = hn::GatherIndex(df, rows.d, at);
    const EvalV below = e.Eval(df, bx, by, bd);
    const MF pop = hn::And(hn::RebindMask(df, two),
                           hn::And(hn::Lt(top.crit, below.crit), hn::Lt(top.sin_h, below.sin_h)));
    if (hn::AllFalse(df, pop)) break;
    st.sp = hn::IfThenElse(hn::RebindMask(di, pop), hn::Sub(st.sp, hn::Set(di, 1)), st.sp);
    st.top_row = hn::IfThenElse(hn::RebindMask(di, pop), below_row, st.top_row);
    st.tx = hn::IfThenElse(pop, bx, st.tx), st.ty = hn::IfThenElse(pop, by, st.ty);
    st.td = hn::IfThenElse(pop, bd, st.td);
    top = Select(pop, below, top);
  }
}

// hull_search: the next `search` entries under the top, not popped; the one that casts most
// replaces the top's evaluation.
HWY_INLINE void SearchHull(DF df, const StepV& e, const Rows& rows, MI has, const StackV& st,
                           int search, EvalV& top) {
  const DI di;
  VI row = st.top_row;
  for (int j = 0; j < search; ++j) {
    const VI level = hn::Sub(st.sp, hn::Set(di, 2 + j));
    const MI in_stack = hn::And(has, hn::Gt(level, hn::Set(di, -1)));
    if (hn::AllFalse(di, in_stack)) break;
    row = rows.Below(in_stack, row);
    const VI at = rows.At(row);
    const EvalV q = e.Eval(df, hn::GatherIndex(df, rows.x, at), hn::GatherIndex(df, rows.y, at),
                           hn::GatherIndex(df, rows.d, at));
    top = Select(hn::And(hn::RebindMask(df, in_stack), hn::Gt(q.crit, top.crit)), q, top);
  }
}

// Algorithm 1 along direction k over the batch's rows: every sample's value (NaN on
// background) into `value`, a row of the layout per step.
HWY_INLINE void SweepAlong(const SweepInputs& in, const BatchLayout& b, SweepScratch& sc, int k,
                           float* value) {
  const DF df;
  const DI di;
  const LsaoPlan& plan = *in.plan;
  const LsaoSettings& set = *in.s;
  const LsaoTangent strategy = LsaoTangent(set.tangent_strategy);
  const bool reversed = plan.reversed[std::size_t(k)];
  const SliceV s = MakeSlice(df, plan.camera, b, plan.directions[std::size_t(k)]);
  const VF inv_r = hn::Set(df, in.inv_r), fixed_v = hn::Set(df, set.tangent_sin);
  std::int32_t* link = sc.link.data();
  const Rows rows{sc.x.data(), sc.y.data(), sc.d.data(), link, hn::Set(di, b.N), hn::Iota(di, 0)};
  StackV st{hn::Zero(di), hn::Zero(di), hn::Zero(df), hn::Zero(df), hn::Zero(df)};
  for (int step = 0; step < b.steps; ++step) {
    const std::size_t t = std::size_t(reversed ? b.steps - 1 - step : step) * std::size_t(b.N);
    const ReceiverV p = LoadReceiver(df, s, sc, t);
    const MF geometry = hn::Eq(p.d, p.d);  // background: no receiver, never an occluder
    const MI geometry_i = hn::RebindMask(di, geometry);
    VF sin_t_hull = fixed_v, sin_t_obscurance = fixed_v;
    if (strategy != LsaoTangent::Fixed) {
      sin_t_obscurance = RealTangentSin(df, in, s, p, geometry_i, fixed_v);
      if (strategy == LsaoTangent::Real) sin_t_hull = sin_t_obscurance;
    }
    const StepV e{s, p, sin_t_hull, inv_r, LsaoFalloff(set.falloff)};
    EvalV top = DropCoincidentTops(df, e, rows, geometry_i, st);
    const MI has = hn::And(geometry_i, hn::Gt(st.sp, hn::Zero(di)));
    PopHull(df, e, rows, has, st, top);
    SearchHull(df, e, rows, has, st, set.hull_search, top);
    // Lines 20 and 28: ρ sin h + (1 − ρ) sin t where sin h > sin t, else sin t.
    const MF occluded = hn::And(hn::RebindMask(df, has), hn::Gt(top.sin_h, sin_t_obscurance));
    VF result = hn::IfThenElse(
        occluded, hn::Add(hn::Mul(top.rho, top.sin_h), hn::Mul(top.rest, sin_t_obscurance)),
        sin_t_obscurance);
    result = hn::IfThenElse(geometry, result, hn::Set(df, kNaN));
    hn::StoreU(result, df, value + t);
    // Line 21: push p. Slots at and above a lane's stack size are dead, so a lane that does
    // not push may write its slot.
    hn::StoreU(st.top_row, di, link + t);  // read only if this row's sample was pushed
    st.sp = hn::IfThenElse(geometry_i, hn::Add(st.sp, hn::Set(di, 1)), st.sp);
    st.top_row =
        hn::IfThenElse(geometry_i, hn::Set(di, std::int32_t(t / std::size_t(b.N))), st.top_row);
    st.tx = hn::IfThenElse(geometry, p.x, st.tx), st.ty = hn::IfThenElse(geometry, p.y, st.ty);
    st.td = hn::IfThenElse(geometry, p.d, st.td);
  }
}

// The values of the batch's directions (`values[n]` for directions_of[li][n]) into the
// buffer's records, in line order.
HWY_INLINE void WriteRecords(const SweepInputs& in, const BatchLayout& b,
                             const float* const values[2]) {
  const LsaoPlan& plan = *in.plan;
  const std::vector<int>& ks = in.directions_of[std::size_t(b.li)];
  const std::size_t stride = std::size_t(plan.stride[std::size_t(b.li)]);
  for (int lane = 0; lane < b.lanes; ++lane) {
    const LsaoLine& line = b.Line(lane);
    float* records = in.buffer + plan.depth_index(b.li, line.offset);
    for (std::size_t n = 0; n < ks.size(); ++n) {
      float* out = records + plan.slot[std::size_t(ks[n])];
      const float* v = values[n] + b.RowOf(lane, 0) * std::size_t(b.N) + std::size_t(lane);
      for (int i = 0; i < line.count; ++i)
        out[std::size_t(i) * stride] = v[std::size_t(i) * std::size_t(b.N)];
    }
  }
}

// How many geometry samples of the batch fall in each bucket of rows: run->bucket_start[b + 1]
// counts bucket b, then the counts are summed into starts. A line's rows are monotonic: its
// samples come in stretches of one bucket, counted with the bucket's counter in a register (a
// counter in memory, incremented per sample, made every sample wait for the previous one's
// store).
HWY_INLINE void CountBuckets(const LsaoPlan& plan, const BatchLayout& b, const SweepScratch& sc,
                             LsaoTexelRun* run) {
  const int buckets = (plan.height + kLsaoRecordRows - 1) / kLsaoRecordRows;
  run->bucket_start.assign(std::size_t(buckets) + 1, 0);
  for (int lane = 0; lane < b.lanes; ++lane) {
    const int n = b.Line(lane).count;
    const float* d = sc.d.data() + b.RowOf(lane, 0) * std::size_t(b.N) + std::size_t(lane);
    const float* y = sc.y.data() + (d - sc.d.data());
    int bucket = -1;
    std::uint32_t count = 0;
    for (int i = 0; i < n; ++i) {
      const std::size_t at = std::size_t(i) * std::size_t(b.N);
      if (!(d[at] == d[at])) continue;
      const int bi = int(y[at]) / kLsaoRecordRows;
      if (bi != bucket) {
        if (bucket >= 0) run->bucket_start[std::size_t(bucket) + 1] += count;
        bucket = bi, count = 0;
      }
      ++count;
    }
    if (bucket >= 0) run->bucket_start[std::size_t(bucket) + 1] += count;
  }
  for (int bi = 0; bi < buckets; ++bi)
    run->bucket_start[std::size_t(bi) + 1] += run->bucket_start[std::size_t(bi)];
}

// The geometry samples by rows of texels for the gather (LsaoTexelRun); buckets filled in line
// order, so each keeps buffer order. Σ w_k O_k in direction order, in double, as the scalar
// gather.
HWY_INLINE void WriteTexelRun(const SweepInputs& in, const BatchLayout& b, SweepScratch& sc,
                              const float* const values[2], LsaoTexelRun* run) {
  const LsaoPlan& plan = *in.plan;
  const std::vector<int>& ks = in.directions_of[std::size_t(b.li)];
  double weight[2] = {0.0, 0.0};
  for (std::size_t n = 0; n < ks.size(); ++n)
    weight[n] = plan.directions[std::size_t(ks[n])].weight;
  run->lines_index = b.li;
  CountBuckets(plan, b, sc, run);
  run->records = in.arena->take(run->bucket_start.back());
  std::vector<std::uint32_t>& cursor = sc.cursor;
  cursor.assign(run->bucket_start.begin(), run->bucket_start.end() - 1);
  LsaoTexelRecord* records = run->records;
  const bool two = ks.size() == 2;
  for (int lane = 0; lane < b.lanes; ++lane) {
    const int n = b.Line(lane).count;
    const std::size_t first = b.RowOf(lane, 0) * std::size_t(b.N) + std::size_t(lane);
    const float *d = sc.d.data() + first, *x = sc.x.data() + first, *y = sc.y.data() + first;
    const float *v0 = values[0] + first, *v1 = values[1] + first;
    int bucket = -1;
    std::uint32_t next = 0;
    for (int i = 0; i < n; ++i) {
      const std::size_t at = std::size_t(i) * std::size_t(b.N);
      const float depth = d[at];
      if (!(depth == depth)) continue;
      const int ty = int(y[at]);
      const int bi = ty / kLsaoRecordRows;
      if (bi != bucket) {
        if (bucket >= 0) cursor[std::size_t(bucket)] = next;
        bucket = bi, next = cursor[std::size_t(bi)];
      }
      double pair = weight[0] * double(v0[at]);
      if (two) pair += weight[1] * double(v1[at]);
      records[next++] = {std::uint16_t(x[at]), std::uint16_t(ty), depth, float(pair)};
    }
    if (bucket >= 0) cursor[std::size_t(bucket)] = next;
  }
}

// Lines [l0, l1) of plan.lines[li] (at most Lanes of them): sampled once, swept in each
// direction that uses them, their records written.
void SweepBatchImpl(const SweepInputs& in, int li, int l0, int l1, SweepScratch& sc,
                    LsaoTexelRun* run) {
  const BatchLayout b = LayOutSamples(in, li, l0, l1, sc);
  const std::vector<int>& ks = in.directions_of[std::size_t(li)];
  for (int k : ks) SweepAlong(in, b, sc, k, (k == ks[0] ? sc.value : sc.value2).data());
  const float* const values[2] = {sc.value.data(), sc.value2.data()};
  if (in.buffer) WriteRecords(in, b, values);
  if (run) WriteTexelRun(in, b, sc, values, run);
}

}  // namespace

// The exported entries (HWY_EXPORT needs namespace-scope functions).
void LsaoGatherBand(const Inputs& in, int band, Scratch& s, float* out) {
  GatherBand(in, band, s, out);
}
void LsaoSweepBatch(const SweepInputs& in, int li, int l0, int l1, SweepScratch& s,
                    LsaoTexelRun* run) {
  SweepBatchImpl(in, li, l0, l1, s, run);
}
int LsaoSweepLanes() { return int(hn::Lanes(DF())); }  // the vector length chosen at run time

}  // namespace aolab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace aolab {

HWY_EXPORT(LsaoGatherBand);
HWY_EXPORT(LsaoSweepBatch);
HWY_EXPORT(LsaoSweepLanes);

namespace {

// Work handed to a thread at a time. A task builds its scratch (the transposed samples and
// links of a batch of lines, ~200 kB; a band's maps and sums) once: one batch or band per task
// spent more time zeroing new scratch than sweeping. Enough tasks remain to balance the
// threads (~50 sweep tasks and ~23 gather tasks at 1280×720).
constexpr int kSweepBatchesPerTask = 16;
constexpr int kGatherBandsPerTask = 2;

// Whether lsao_gather_simd's texel maps hold every sample at its own place: aligned sets (their
// lines are lines of texel centres) with snapped samples. Otherwise (interpolated samples sit
// between texels; a uniform set's snapped samples are not ordered across by their lines, so
// the stencil's order is not the tie rule) the scalar gather runs.
bool texel_maps_apply(const LsaoPlan& plan, const LsaoSettings& s) {
  const bool aligned =
      std::all_of(plan.directions.begin(), plan.directions.end(),
                  [](const SweepDirection& d) { return d.lattice_x != 0 || d.lattice_y != 0; });
  return aligned && LsaoSampling(s.sampling) == LsaoSampling::Snap && plan.width <= 65535 &&
         plan.height <= 65535;  // LsaoTexelRecord's coordinates
}

// The axes and their stencils: the texel offsets within the direction's gather radius (the
// scalar code's spans), nearest first; equal distances in the order the scalar code offers
// samples — lines in increasing order across the sweep, then samples along it — so the first
// of equally near passing samples is the scalar code's pick.
std::vector<lsao_simd::Axis> make_axes(const LsaoPlan& plan, const std::vector<LsaoTexelRun>& runs,
                                       double line_spacing, int& reach) {
  std::vector<lsao_simd::Axis> axes(plan.lines.size());
  reach = 0;
  for (std::size_t li = 0; li < plan.lines.size(); ++li) {
    lsao_simd::Axis& a = axes[li];
    a.lines = int(li);
    const SweepDirection& d = plan.directions[std::size_t(plan.lines[li].direction)];
    const double radius = lsao_gather_radius(d, line_spacing), radius2 = radius * radius;
    const int r = int(radius);
    reach = std::max(reach, r);
    for (int dy = -r; dy <= r; ++dy) {
      int span = 0;
      while (double((span + 1) * (span + 1) + dy * dy) <= radius2) ++span;
      for (int dx = -span; dx <= span; ++dx) a.stencil.push_back({dx, dy});
    }
    // Line l's samples lie across at (phase + l·D_L) along (−u_y, u_x); along it, sample j at
    // j·step: the offset's projections order them as the buffer does.
    const double sx = d.step_x, sy = d.step_y;
    std::stable_sort(a.stencil.begin(), a.stencil.end(),
                     [&](const lsao_simd::Offset& p, const lsao_simd::Offset& q) {
                       const int dp = p.dx * p.dx + p.dy * p.dy, dq = q.dx * q.dx + q.dy * q.dy;
                       if (dp != dq) return dp < dq;
                       const double ap = -p.dx * sy + p.dy * sx, aq = -q.dx * sy + q.dy * sx;
                       if (ap != aq) return ap < aq;
                       return p.dx * sx + p.dy * sy < q.dx * sx + q.dy * sy;
                     });
  }
  for (int k = 0; k < int(plan.directions.size()); ++k) {
    lsao_simd::Axis& a = axes[std::size_t(plan.lines_of[std::size_t(k)])];
    a.k[a.k[0] < 0 ? 0 : 1] = k;
  }
  for (std::size_t r = 0; r < runs.size(); ++r) {  // runs are in plan.lines order
    lsao_simd::Axis& a = axes[std::size_t(runs[r].lines_index)];
    if (a.end_run == 0) a.first_run = r;
    a.end_run = r + 1;
  }
  for (lsao_simd::Axis& a : axes) {
    double w = 0.0;
    for (int k : a.k)
      if (k >= 0) w += plan.directions[std::size_t(k)].weight;
    a.pair_weight = float(w);
  }
  return axes;
}

}  // namespace

namespace {

Image gather_simd(const GBuffer& g, const LsaoSettings& s, const LsaoSweep& sweep,
                  const RunOptions& options, const Buffer<float>* frame_depth) {
  const LsaoPlan& plan = sweep.plan;
  // Without texel records (another setting, or a sweep from lsao_sweep) the scalar gather.
  if (!texel_maps_apply(plan, s) || sweep.texel_runs.empty())
    return lsao_gather(g, s, sweep, options);
  CHECK_EQ(plan.width, g.width());
  CHECK_EQ(plan.height, g.height());
  const int w = g.width(), h = g.height();
  const int threads = resolve_threads(options.threads);
  const Buffer<float> depth =
      frame_depth ? Buffer<float>() : depth_with_background_as_nan(g, threads);
  Image normals;
  if (s.normal_aware_gather) normals = prepared_normals(g, threads);

  lsao_simd::Inputs in;
  in.plan = &plan;
  in.sweep = &sweep;
  in.axes = make_axes(plan, sweep.texel_runs, s.line_spacing, in.reach);
  in.depth = frame_depth ? frame_depth->data() : depth.data();
  in.normals = normals.data();
  in.normal_aware = s.normal_aware_gather;
  in.tolerance = s.gather_depth_tolerance;
  in.width = w, in.height = h;
  // Columns: reach on the left; on the right reach and a whole vector, so a row's last vector
  // reads the map past its end (those lanes are dropped).
  in.pad_left = in.reach;
  in.map_stride = in.reach + w + in.reach + HWY_DYNAMIC_DISPATCH(LsaoSweepLanes)();
  in.map_rows = lsao_simd::kBandRows + 2 * in.reach;

  Image out(w, h, 1, 1.0f);
  const int bands = (h + lsao_simd::kBandRows - 1) / lsao_simd::kBandRows;
  if (options.progress) options.progress->total += bands;
  // A band clears the maps and sums it reads before it fills them.
  ScratchPool<lsao_simd::Scratch> scratches;
  parallel_for_rows(
      bands, threads,
      [&](int b0, int b1) {
        auto scratch = scratches.take([&] { return std::make_unique<lsao_simd::Scratch>(in); });
        for (int b = b0; b < b1; ++b)
          HWY_DYNAMIC_DISPATCH(LsaoGatherBand)(in, b, *scratch, out.data());
        scratches.give(std::move(scratch));
      },
      options.progress, kGatherBandsPerTask);
  return out;
}

LsaoSweep sweep_simd(const GBuffer& g, const LsaoSettings& s, const RunOptions& options,
                     bool keep_buffer, const Buffer<float>* frame_depth) {
  g.validate();
  LsaoSweep sweep;
  sweep.plan = lsao_plan(g, s);
  const LsaoPlan& plan = sweep.plan;
  const int threads = resolve_threads(options.threads);
  const Buffer<float> depth =
      frame_depth ? Buffer<float>() : depth_with_background_as_nan(g, threads);
  Image normals;
  if (LsaoTangent(s.tangent_strategy) != LsaoTangent::Fixed) normals = prepared_normals(g, threads);

  lsao_simd::SweepInputs in;
  in.plan = &plan;
  in.s = &s;
  in.depth = frame_depth ? frame_depth->data() : depth.data();
  in.normals = normals.data();
  const double radius = s.radius;
  in.inv_r = float(1.0 / (double(kLsaoFalloffOffset) * radius * radius));
  in.directions_of.resize(plan.lines.size());
  for (int k = 0; k < int(plan.directions.size()); ++k)
    in.directions_of[std::size_t(plan.lines_of[std::size_t(k)])].push_back(k);
  in.texel_runs = texel_maps_apply(plan, s);
  // The gather reads the texel runs where they apply; the buffer is then only for callers that
  // ask for it (the scalar gather, tests).
  if (keep_buffer || !in.texel_runs)
    sweep.buffer.assign(plan.buffer_size, std::numeric_limits<float>::quiet_NaN());
  in.buffer = sweep.buffer.empty() ? nullptr : sweep.buffer.data();

  // Batches of Lanes consecutive lines of one set (their lengths differ little, so few lanes
  // idle). A line's values depend on its own lane only: the same bits for any thread count.
  const int lanes = HWY_DYNAMIC_DISPATCH(LsaoSweepLanes)();
  struct Batch {
    int li, l0, l1;
  };
  std::vector<Batch> batches;
  for (int li = 0; li < int(plan.lines.size()); ++li) {
    const auto& ls = plan.lines[std::size_t(li)].lines;
    int l = 0;
    while (l < int(ls.size())) {
      if (ls[std::size_t(l)].count == 0) {
        ++l;
        continue;
      }
      int e = l;
      while (e < int(ls.size()) && e - l < lanes && ls[std::size_t(e)].count > 0) ++e;
      batches.push_back({li, l, e});
      l = e;
    }
  }
  if (in.texel_runs) {
    sweep.texel_runs.resize(batches.size());
    sweep.record_arena = std::make_unique<LsaoRecordArena>();
  }
  in.arena = sweep.record_arena.get();
  if (options.progress) options.progress->total += std::int64_t(batches.size());
  // A batch writes every element of the scratch it reads.
  ScratchPool<lsao_simd::SweepScratch> scratches;
  parallel_for_rows(
      int(batches.size()), threads,
      [&](int b0, int b1) {
        auto scratch = scratches.take([] { return std::make_unique<lsao_simd::SweepScratch>(); });
        for (int b = b0; b < b1; ++b) {
          const Batch& batch = batches[std::size_t(b)];
          HWY_DYNAMIC_DISPATCH(LsaoSweepBatch)
          (in, batch.li, batch.l0, batch.l1, *scratch,
           in.texel_runs ? &sweep.texel_runs[std::size_t(b)] : nullptr);
        }
        scratches.give(std::move(scratch));
      },
      options.progress, kSweepBatchesPerTask);
  return sweep;
}

}  // namespace

Image lsao_gather_simd(const GBuffer& g, const LsaoSettings& s, const LsaoSweep& sweep,
                       const RunOptions& options) {
  return gather_simd(g, s, sweep, options, nullptr);
}

LsaoSweep lsao_sweep_simd(const GBuffer& g, const LsaoSettings& s, const RunOptions& options,
                          bool keep_buffer) {
  return sweep_simd(g, s, options, keep_buffer, nullptr);
}

Image lsao_simd_kernel(const GBuffer& g, const LsaoSettings& s, const RunOptions& options) {
  g.validate();
  validate_lsao_settings(s);
  // Both phases read the depth with background as NaN: made once.
  const Buffer<float> depth = depth_with_background_as_nan(g, resolve_threads(options.threads));
  return gather_simd(g, s, sweep_simd(g, s, options, false, &depth), options, &depth);
}

}  // namespace aolab
#endif  // HWY_ONCE
