#include "core/methods/lsao/lsao.h"

#include <cstdint>
#include <limits>
#include <numbers>
#include <numeric>
#include <string>

#include "core/base/check.h"
#include "core/base/parallel.h"
#include "core/methods/lsao/lsao_shared.h"
#include "core/sampling/random.h"

namespace aolab {

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// floor for |x| < 2^62 by truncation: std::floor is a library call on baseline x86-64, and
// the sampling and the gather floor every coordinate they touch.
inline long long floor_ll(double x) {
  const long long t = (long long)x;
  return t - (double(t) > x ? 1 : 0);
}

// Integers (p, q) with −p·b + q·a = 1 for coprime a, b (|a|, |b| ≤ 8 here): the offset that
// moves a texel centre onto the next lattice line of direction (a, b).
void unit_lattice_step(int a, int b, int& p, int& q) {
  const int range = std::abs(a) + std::abs(b) + 1;
  for (p = -range; p <= range; ++p)
    for (q = -range; q <= range; ++q)
      if (-p * b + q * a == 1) return;
  CHECK_EQ(std::gcd(std::abs(a), std::abs(b)), 1);  // unreachable for coprime a, b
}

// The range of j whose sample position lies inside the image, found by solving the bounds in
// double and then settling the ends with the exact position formula.
void sample_range(LsaoLine& line, const SweepDirection& d, int w, int h) {
  double lo = -1e18, hi = 1e18;
  auto bound = [&](double origin, double step, double size) {
    if (step > 0) {
      lo = std::max(lo, (0.0 - origin) / step);
      hi = std::min(hi, (size - origin) / step);
    } else if (step < 0) {
      lo = std::max(lo, (size - origin) / step);
      hi = std::min(hi, (0.0 - origin) / step);
    } else if (!(origin >= 0.0 && origin < size)) {
      lo = 1.0, hi = 0.0;
    }
  };
  bound(line.origin_x, d.step_x, double(w));
  bound(line.origin_y, d.step_y, double(h));
  line.first = 0, line.count = 0;
  if (!(lo <= hi + 2.0)) return;
  auto inside = [&](long long j) {
    double x, y;
    lsao_sample_position(line, d, int(j), x, y);
    return x >= 0.0 && x < double(w) && y >= 0.0 && y < double(h);
  };
  long long first = (long long)std::ceil(lo) - 1, last = (long long)std::floor(hi) + 1;
  while (first <= last && !inside(first)) ++first;
  while (last >= first && !inside(last)) --last;
  if (first > last) return;
  line.first = int(first);
  line.count = int(last - first + 1);
}

// §5.1 line placement: lines `spacing` = D_L apart across the direction, the lattice of line
// 0 / sample 0 through the image centre (plus a seeded offset). For aligned sets (§5.2) each
// line is moved onto the nearest line of texel centres along the direction and its origin
// onto a texel centre, so that every sample is a texel centre.
LsaoLines place_lines(const SweepDirection& d, int direction, int w, int h, const LsaoSettings& s) {
  LsaoLines out;
  out.direction = direction;
  const double len = d.step_length();
  const double ux = d.step_x / len, uy = d.step_y / len;
  out.across_x = -uy, out.across_y = ux;
  out.spacing = s.line_spacing;
  const double cx = 0.5 * w, cy = 0.5 * h;  // image centre, pixels
  double phase_along = 0.0;
  out.phase_across = 0.0;
  if (s.seed > 0) {  // one offset per direction pair: opposite sweeps keep sharing samples
    out.phase_across = pixel_random(std::uint32_t(s.seed), direction, 0, 0) * s.line_spacing;
    phase_along = pixel_random(std::uint32_t(s.seed), direction, 0, 1) * len;
  }
  // Extent of the texel centres across the lines.
  double lo = 1e300, hi = -1e300;
  for (double px : {0.5, w - 0.5})
    for (double py : {0.5, h - 0.5}) {
      const double a = (px - cx) * out.across_x + (py - cy) * out.across_y;
      lo = std::min(lo, a), hi = std::max(hi, a);
    }
  // One spare line each side: snapping can bring a line just outside the extent inside.
  out.first_line = int(std::floor((lo - 1.0 - out.phase_across) / out.spacing));
  const int last_line = int(std::ceil((hi + 1.0 - out.phase_across) / out.spacing));

  const bool aligned = d.lattice_x != 0 || d.lattice_y != 0;
  int p = 0, q = 0;
  double tx = 0, ty = 0, lattice_len = 0;
  if (aligned) {
    unit_lattice_step(d.lattice_x, d.lattice_y, p, q);
    tx = std::floor(cx) + 0.5, ty = std::floor(cy) + 0.5;  // the texel centre nearest (cx, cy)
    lattice_len = std::hypot(double(d.lattice_x), double(d.lattice_y));
  }
  for (int l = out.first_line; l <= last_line; ++l) {
    const double across = out.phase_across + l * out.spacing;
    LsaoLine line;
    if (aligned) {
      // Texel centres T0 + (i, j) lie on the lattice lines −i·b + j·a = k, 1/|(a, b)| apart.
      const double rel_across = across + (cx - tx) * out.across_x + (cy - ty) * out.across_y;
      const long long k = std::llround(rel_across * lattice_len);
      const double bx = double(k * p), by = double(k * q);  // a texel offset on lattice line k
      const double target_along = (cx - tx) * ux + (cy - ty) * uy + phase_along;
      const double base_along = (bx * d.lattice_x + by * d.lattice_y) / lattice_len;
      const long long lambda = std::llround((target_along - base_along) / lattice_len);
      line.origin_x = tx + bx + double(lambda * d.lattice_x);
      line.origin_y = ty + by + double(lambda * d.lattice_y);
    } else {
      line.origin_x = cx + across * out.across_x + phase_along * ux;
      line.origin_y = cy + across * out.across_y + phase_along * uy;
    }
    sample_range(line, d, w, h);
    line.offset = out.samples;
    out.samples += std::size_t(line.count);
    out.lines.push_back(line);
  }
  return out;
}

// The 2-D space in which eq. 1 is evaluated. The paper projects onto the vertical plane along
// the azimuth, p_k = (p_xy·D_k, p_z) (§3): exact for the line through the principal point,
// but a line off it does not lie in that plane, which shortens its distances and tilts its
// elevations. We use the plane that holds the line and the eye, with axes b1 = (D, 0) and
// b2 = (c_L·E, −1)/κ, where E is D turned by +90°, c_L = o·E for the points o of the line in
// normalised image coordinates o = ((x − cx)/fx, −(y − cy)/fy), and κ = √(1 + c_L²). A point
// X = d·(o, −1) of the line has there the coordinates
//   a = X·b1 = d (o·D),   z = −X·b2 = −κ d,
// the paper's (p_xy·D, p_z) with the depth axis stretched by κ. Samples snapped off the line
// get the same formula — they are moved onto the plane along (E, 0), at constant depth — so
// that a plane of constant depth stays level whatever the snapping (§5.2's artefact remains
// only where the depth itself changes). With c_L = 0 this is the paper's projection exactly.
struct Slice {
  float dx, dy;              // D, unit, in normalised image coordinates (view x, y)
  float ex, ey;              // E = (−D.y, D.x)
  float along_fx, along_fy;  // Δo·D per pixel offset: D.x/fx, −D.y/fy
  float c_line;              // c_L
  float kappa;               // √(1 + c_L²)
  float cx, cy;
};

Slice make_slice(const LsaoPlan& plan, int k, const LsaoLine& line) {
  const SweepDirection& d = plan.directions[k];
  const CameraIntrinsics& cam = plan.camera;
  // D from the direction's own step (negated for the opposite sweep, exactly).
  const double ox = d.step_x / cam.fx, oy = -d.step_y / cam.fy;
  const double len = std::hypot(ox, oy);
  Slice s;
  s.dx = float(ox / len), s.dy = float(oy / len);
  s.ex = -s.dy, s.ey = s.dx;
  s.along_fx = float(double(s.dx) / cam.fx), s.along_fy = float(-double(s.dy) / cam.fy);
  const double c =
      (line.origin_x - cam.cx) / cam.fx * s.ex - (line.origin_y - cam.cy) / cam.fy * s.ey;
  s.c_line = float(c);
  s.kappa = float(std::sqrt(1.0 + c * c));
  s.cx = cam.cx, s.cy = cam.cy;
  return s;
}

struct HullPoint {
  float x, y, d;
};

// The receiver p in its slice: û, the unit vector towards the eye (Algorithm 1, line 7:
// uk = −pk/‖pk‖), and o_p·D, which lets h = q − p be formed without cancellation.
struct Receiver {
  float x, y, d;
  float o_along;  // o_p·D
  float ua, uz;   // û
};

Receiver make_receiver(const Slice& s, const LsaoSample& q) {
  Receiver r;
  r.x = q.x, r.y = q.y, r.d = q.depth;
  r.o_along = (q.x - s.cx) * s.along_fx + (q.y - s.cy) * s.along_fy;
  // p = d·(o_along, −κ); û = −p/‖p‖: the depth cancels.
  const float ua = -r.o_along, uz = s.kappa;
  const float len = std::sqrt(ua * ua + uz * uz);
  r.ua = ua / len, r.uz = uz / len;
  return r;
}

// h = q − p (eq. 1's vector to the occluder) from pixel offsets and the depth difference:
// a_q − a_p = d_q (Δo·D) + (o_p·D)(d_q − d_p) and z_q − z_p = −κ (d_q − d_p), exact in
// exact arithmetic; it never subtracts two large coordinates.
inline void slice_vector(const Slice& s, const Receiver& p, const HullPoint& q, float& ha,
                         float& hz) {
  const float dx = q.x - p.x, dy = q.y - p.y, dd = q.d - p.d;
  ha = q.d * (dx * s.along_fx + dy * s.along_fy) + p.o_along * dd;
  hz = -s.kappa * dd;
}

// sin t of the receiver's real tangent plane (§4.1 strategies 1, 2) in the slice: with
// n2 = the normal projected on the slice, e = the unit vector ⟂ û on the side of the earlier
// samples, the free directions w = cos φ e + sin φ û satisfy w·n2 ≥ 0, i.e. φ ≥ t with
//   sin t = −(n2·e) / √((n2·e)² + (n2·û)²)
// (the paper's t_k = (−n_z, n_xy·D_k), sin t = t̂·û, in the slice's own axes). A normal
// turned away from the eye within the slice (n2·û ≤ 0) takes the limit n2·û → 0+; a normal
// perpendicular to the slice has no tangent in it and keeps the fixed one.
float real_tangent_sin(const Slice& s, const Receiver& p, const float* n, float fixed) {
  const float na = n[0] * s.dx + n[1] * s.dy;
  const float nz = (n[2] - s.c_line * (n[0] * s.ex + n[1] * s.ey)) / s.kappa;
  const float ne = -na * p.uz + nz * p.ua;  // e = (−u_z, u_a) points to decreasing a
  const float nu = std::max(0.0f, na * p.ua + nz * p.uz);
  const float den = std::sqrt(ne * ne + nu * nu);
  return den > 0.0f ? -ne / den : fixed;
}

struct Context {
  const LsaoPlan& plan;
  const LsaoSettings& s;
  const float* normals;  // prepared, 3 per pixel; null if no setting needs them
  float inv_r;           // 1/r = 1/(C R²)
  LsaoFalloff falloff;
  LsaoTangent strategy;
  LsaoSampling sampling;
};

struct Evaluation {
  float crit;   // max(0, sin h − sin t_hull) · ρ: eq. 1 without its constant sin t
  float sin_h;  // ĥ·û
  LsaoWeight weight;
  bool zero;  // q is p itself (two samples snapped to one texel)
};

inline Evaluation evaluate(const Context& c, const Slice& s, const Receiver& p, const HullPoint& q,
                           float sin_t_hull) {
  float ha, hz;
  slice_vector(s, p, q, ha, hz);
  const float len2 = ha * ha + hz * hz;
  if (len2 == 0.0f) return {0.0f, 0.0f, {0.0f, 1.0f}, true};
  const float sin_h = (ha * p.ua + hz * p.uz) / std::sqrt(len2);
  const LsaoWeight weight = lsao_falloff(len2 * c.inv_r, c.falloff);  // d²/r; overflow: ρ = 0
  return {std::max(0.0f, sin_h - sin_t_hull) * weight.rho, sin_h, weight, false};
}

// Algorithm 1 for one line in one direction; `reversed` walks the line from its last sample
// (the opposite direction). values[i·stride] receives O at sample i.
void sweep_line(const Context& c, const Slice& s, const std::vector<LsaoSample>& samples,
                bool reversed, float* values, std::size_t stride, std::vector<HullPoint>& hull) {
  hull.clear();
  const int n = int(samples.size());
  const float fixed = c.s.tangent_sin;
  const int width = c.plan.width;
  for (int step = 0; step < n; ++step) {
    const int i = reversed ? n - 1 - step : step;
    const LsaoSample& q = samples[i];
    if (!(q.depth == q.depth)) {  // background: no receiver, never an occluder
      values[i * stride] = kNaN;
      continue;
    }
    const Receiver p = make_receiver(s, q);
    float sin_t_hull = fixed, sin_t_obscurance = fixed;  // strategy 3
    if (c.strategy != LsaoTangent::Fixed) {
      const float* nrm = c.normals + 3 * (std::size_t(int(q.y)) * width + std::size_t(int(q.x)));
      sin_t_obscurance = real_tangent_sin(s, p, nrm, fixed);
      if (c.strategy == LsaoTangent::Real) sin_t_hull = sin_t_obscurance;
    }
    // A point at p's own position (the previous sample snapped to the same texel) is not an
    // occluder; p replaces it on the stack below.
    Evaluation top{};
    while (!hull.empty()) {
      top = evaluate(c, s, p, hull.back(), sin_t_hull);
      if (!top.zero) break;
      hull.pop_back();
    }
    float result = sin_t_obscurance;  // no earlier point: h = t, eq. 1 gives sin t
    if (!hull.empty()) {
      // Algorithm 1, lines 12–18: pop while the top casts less obscurance than the point
      // below it and lies below it (h1·u/‖h1‖ < h2·u/‖h2‖).
      while (hull.size() >= 2) {
        const Evaluation below = evaluate(c, s, p, hull[hull.size() - 2], sin_t_hull);
        if (!(top.crit < below.crit && top.sin_h < below.sin_h)) break;
        hull.pop_back();
        top = below;
      }
      // Extension (hull_search > 0): the loop stops at a top that is higher than the entry
      // below it, even when that entry, nearer in view space, casts more; look a bounded
      // number of entries further down, without popping.
      const int last = int(hull.size()) - 2;
      for (int j = last; j >= 0 && last - j < c.s.hull_search; --j) {
        const Evaluation e = evaluate(c, s, p, hull[j], sin_t_hull);
        if (e.crit > top.crit) top = e;
      }
      // Line 20: writeResult(occlusion(h1, uk)); line 28: sin t + max(0, sin h − sin t)·ρ,
      // written as ρ·sin h + (1 − ρ)·sin t so that ρ = 1 gives sin h exactly and opposite
      // sweeps over a plane (sin h and −sin h) cancel to the bit.
      if (top.sin_h > sin_t_obscurance)
        result = top.weight.rho * top.sin_h + top.weight.one_minus_rho * sin_t_obscurance;
    }
    values[i * stride] = result;
    hull.push_back({q.x, q.y, q.depth});  // line 21
  }
}

// ---- The gather (§5.1) ----

// A direction and its opposite share their samples (§5.1 lines, walked both ways) and so
// their candidates: the gather searches once per `plan.lines` entry ("axis").
struct GatherAxis {
  double radius, radius2;  // gather radius, pixels
  int k[2];                // the directions that use the axis (k[1] = −1 if only one)
  // Texel-centre samples reach the pixels (tx + dx, ty + dy) with dx² + dy² ≤ radius²:
  // per dy in [−reach, reach], |dx| ≤ span[dy + reach].
  int reach;
  std::vector<int> span;
};

std::vector<GatherAxis> gather_axes(const LsaoPlan& plan, double line_spacing) {
  std::vector<GatherAxis> axes(plan.lines.size());
  for (std::size_t li = 0; li < plan.lines.size(); ++li) {
    GatherAxis& a = axes[li];
    a.radius = lsao_gather_radius(plan.directions[plan.lines[li].direction], line_spacing);
    a.radius2 = a.radius * a.radius;
    a.k[0] = a.k[1] = -1;
    a.reach = int(a.radius);
    for (int dy = -a.reach; dy <= a.reach; ++dy) {
      int dx = 0;
      while (double((dx + 1) * (dx + 1) + dy * dy) <= a.radius2) ++dx;
      a.span.push_back(dx);
    }
  }
  for (int k = 0; k < int(plan.directions.size()); ++k) {
    GatherAxis& a = axes[plan.lines_of[k]];
    a.k[a.k[0] < 0 ? 0 : 1] = k;
  }
  return axes;
}

// The samples j of `line` whose line position lies within rows [lo, hi] (an interval of j);
// false if the line cannot reach them.
bool samples_within_rows(const LsaoLine& line, const SweepDirection& d, double lo, double hi,
                         long long& j_lo, long long& j_hi) {
  if (line.count == 0) return false;
  j_lo = line.first, j_hi = line.first + line.count - 1;
  if (d.step_y == 0.0) return line.origin_y >= lo && line.origin_y <= hi;
  const double ja = (lo - line.origin_y) / d.step_y, jb = (hi - line.origin_y) / d.step_y;
  j_lo = std::max(j_lo, -floor_ll(-std::min(ja, jb)));
  j_hi = std::min(j_hi, floor_ll(std::max(ja, jb)));
  return true;
}

// What every band of the gather reads.
struct GatherInputs {
  const LsaoPlan& plan;
  const LsaoSweep& sweep;
  const std::vector<GatherAxis>& axes;
  const float* depth;    // W·H, background as NaN
  const float* normals;  // prepared, 3 per pixel; read only if normal_aware
  bool normal_aware;
  float tolerance;  // gather_depth_tolerance
  bool interpolated;
  int width, height;
};

// Rows per gather band. Each band visits, per axis, the samples within the gather radius of
// its rows — short runs of consecutive samples of each line, read in order — and offers each
// to the pixels within the radius (a scatter: per pixel and direction a search of the lines
// around it read scattered samples and ran ~8× slower). Lines in order, samples in line order
// and a strict "nearer" test make the choice between equally near samples the first one,
// whatever the band: the result does not depend on threads. 16 rows: a sample is read by
// about (16 + 2·radius)/16 bands, and a band's per-pixel state stays within a few hundred kB
// at 1920 columns.
constexpr int kGatherRows = 16;

// One band of rows being gathered: per pixel, the nearest sample of the current axis that
// passes the tests (best, pick) and the nearest regardless (best_any, pick_any), and the
// coverage-weighted sums of the values chosen so far over the axes.
class GatherBand {
 public:
  explicit GatherBand(const GatherInputs& in) : in_(in) {
    const std::size_t n = std::size_t(kGatherRows) * in.width;
    for (auto* v : {&sum_, &weight_, &sum_any_, &weight_any_, &best_, &best_any_}) v->resize(n);
    pick_.resize(n), pick_any_.resize(n);
  }

  // Gathers band `band` into `out`.
  void run(int band, Image& out) {
    y0_ = band * kGatherRows, y1_ = std::min(in_.height, y0_ + kGatherRows);
    for (auto* v : {&sum_, &weight_, &sum_any_, &weight_any_}) std::fill(v->begin(), v->end(), 0.0);
    for (std::size_t li = 0; li < in_.axes.size(); ++li) {
      std::fill(best_.begin(), best_.end(), INFINITY);
      std::fill(best_any_.begin(), best_any_.end(), INFINITY);
      visit_axis(int(li));
      add_axis(in_.axes[li]);
    }
    write(out);
  }

 private:
  // Offers every geometry sample of axis li that can reach a pixel of the band.
  void visit_axis(int li) {
    const GatherAxis& a = in_.axes[std::size_t(li)];
    const LsaoLines& lines = in_.plan.lines[std::size_t(li)];
    const SweepDirection& d = in_.plan.directions[lines.direction];
    // Samples whose evaluated position can be within the radius of a pixel centre of the
    // band (snapping moves a sample by less than 1 px from its line position).
    const double lo = y0_ + 0.5 - a.radius - 1.0, hi = y1_ - 0.5 + a.radius + 1.0;
    for (const LsaoLine& line : lines.lines) {
      long long j_lo, j_hi;
      if (!samples_within_rows(line, d, lo, hi, j_lo, j_hi)) continue;
      for (long long j = j_lo; j <= j_hi; ++j) {
        const std::size_t i = line.offset + std::size_t(j - line.first);
        const float dq = in_.sweep.depth(li, i);
        if (!(dq == dq)) continue;  // background sample: no value
        double sx, sy;
        lsao_sample_position(line, d, int(j), sx, sy);
        const long long tx = floor_ll(sx), ty = floor_ll(sy);
        const float* nq = in_.normal_aware
                              ? in_.normals + 3 * (std::size_t(ty) * in_.width + std::size_t(tx))
                              : nullptr;
        if (in_.interpolated)
          offer_around_point(a, i, dq, nq, sx, sy);
        else
          offer_around_texel(a, i, dq, nq, int(tx), int(ty));
      }
    }
  }

  // A sample evaluated at the centre of texel (tx, ty): the stencil of whole-pixel offsets.
  void offer_around_texel(const GatherAxis& a, std::size_t i, float dq, const float* nq, int tx,
                          int ty) {
    const int ya = std::max<int>(y0_, ty - a.reach);
    const int yb = std::min<int>(y1_ - 1, ty + a.reach);
    for (int y = ya; y <= yb; ++y) {
      const int dy = y - ty, span = a.span[std::size_t(dy + a.reach)];
      const int xa = std::max<int>(0, tx - span);
      const int xb = std::min<int>(in_.width - 1, tx + span);
      for (int x = xa; x <= xb; ++x) {
        const int dx = x - tx;
        offer(i, dq, nq, x, y, double(dx * dx + dy * dy));
      }
    }
  }

  // A sample evaluated at (sx, sy), between texel centres: the pixels within the radius.
  void offer_around_point(const GatherAxis& a, std::size_t i, float dq, const float* nq, double sx,
                          double sy) {
    const int ya = std::max<int>(y0_, int(-floor_ll(-(sy - 0.5 - a.radius))));
    const int yb = std::min<int>(y1_ - 1, int(floor_ll(sy - 0.5 + a.radius)));
    for (int y = ya; y <= yb; ++y) {
      const double dy = y + 0.5 - sy;
      const double half = std::sqrt(std::max(0.0, a.radius2 - dy * dy));
      const int xa = std::max<int>(0, int(-floor_ll(-(sx - 0.5 - half))));
      const int xb = std::min<int>(in_.width - 1, int(floor_ll(sx - 0.5 + half)));
      for (int x = xa; x <= xb; ++x) {
        const double dx = x + 0.5 - sx, dist2 = dx * dx + dy * dy;
        if (dist2 <= a.radius2) offer(i, dq, nq, x, y, dist2);
      }
    }
  }

  // Sample i (depth dq, normal nq) offered to pixel (x, y) at squared distance dist2.
  void offer(std::size_t i, float dq, const float* nq, int x, int y, double dist2) {
    const std::size_t p = std::size_t(y - y0_) * in_.width + std::size_t(x);
    if (!(dist2 < best_any_[p] || dist2 < best_[p])) return;
    const float dp = in_.depth[std::size_t(y) * in_.width + x];
    if (!(dp == dp)) return;  // background pixel: 1
    if (dist2 < best_any_[p]) best_any_[p] = dist2, pick_any_[p] = i;
    if (!(dist2 < best_[p])) return;
    if (!(std::abs(dq - dp) <= in_.tolerance * dp)) return;  // §5.1, depth-aware
    if (nq) {                                                // §5.1, normal-aware
      const float* np = in_.normals + 3 * (std::size_t(y) * in_.width + x);
      if (!(np[0] * nq[0] + np[1] * nq[1] + np[2] * nq[2] >= kLsaoGatherNormalCos)) return;
    }
    best_[p] = dist2, pick_[p] = i;
  }

  // Adds the picks of an axis: both its directions at once, their pair sum as one term, so a
  // pair that cancels (a plane) adds exactly 0.
  void add_axis(const GatherAxis& a) {
    const std::size_t used = std::size_t(y1_ - y0_) * in_.width;
    for (std::size_t p = 0; p < used; ++p)
      for (int with_test = 0; with_test < 2; ++with_test) {
        if (!((with_test ? best_[p] : best_any_[p]) < INFINITY)) continue;
        const std::size_t i = with_test ? pick_[p] : pick_any_[p];
        double pair = 0.0, pair_weight = 0.0;
        for (int k : a.k) {
          if (k < 0) continue;
          pair += in_.plan.directions[k].weight * double(in_.sweep.value(k, i));
          pair_weight += in_.plan.directions[k].weight;
        }
        (with_test ? sum_ : sum_any_)[p] += pair;
        (with_test ? weight_ : weight_any_)[p] += pair_weight;
      }
  }

  void write(Image& out) const {
    for (int y = y0_; y < y1_; ++y)
      for (int x = 0; x < in_.width; ++x) {
        const std::size_t p = std::size_t(y - y0_) * in_.width + std::size_t(x);
        // Every direction failed the tests (a thin feature between sparse samples): the
        // nearest values regardless, so that no geometry pixel is left without one.
        const bool tested = weight_[p] > 0.0;
        const double total = tested ? weight_[p] : weight_any_[p];
        // A = 1 − Σ w_k O_k / Σ w_k (eq. 1 with the coverage weights of §5.2).
        if (total > 0.0)
          out(x, y) = float(std::clamp(1.0 - (tested ? sum_[p] : sum_any_[p]) / total, 0.0, 1.0));
      }
  }

  const GatherInputs& in_;
  int y0_ = 0, y1_ = 0;
  std::vector<double> sum_, weight_, sum_any_, weight_any_, best_, best_any_;
  std::vector<std::size_t> pick_, pick_any_;
};

}  // namespace

void validate_lsao_settings(const LsaoSettings& s) {
  validate_settings(s, kLsaoFields);
  if (s.template_size > 0 && s.directions != 8 * s.template_size)
    throw_invalid("directions",
                  "must be 8 x template_size = " + std::to_string(8 * s.template_size) +
                      " when template_size is " + std::to_string(s.template_size) +
                      " (a (2n+1)^2 template gives 8n aligned directions; template_size = 0 "
                      "gives K uniform directions)",
                  s.directions);
}

LsaoPlan lsao_plan(const GBuffer& g, const LsaoSettings& s) {
  validate_lsao_settings(s);
  LsaoPlan plan;
  plan.width = g.width(), plan.height = g.height();
  plan.camera = g.camera;
  plan.directions = s.template_size > 0
                        ? aligned_sweep_directions(s.template_size, s.template_stride, g.camera)
                        : uniform_sweep_directions(s.directions, s.step, g.camera);
  const int k = int(plan.directions.size());
  plan.lines_of.assign(k, -1);
  plan.reversed.assign(k, false);
  for (int i = 0; i < k; ++i) {
    const int opp = plan.directions[i].opposite;
    if (opp >= 0 && opp < i) {  // the opposite sweep runs the same lines backwards (§5.1)
      plan.lines_of[i] = plan.lines_of[opp];
      plan.reversed[i] = true;
    } else {
      plan.lines_of[i] = int(plan.lines.size());
      plan.lines.push_back(place_lines(plan.directions[i], i, plan.width, plan.height, s));
    }
  }
  plan.stride.assign(plan.lines.size(), 1);
  plan.slot.assign(k, 0);
  for (int i = 0; i < k; ++i) {
    plan.slot[i] = plan.stride[plan.lines_of[i]]++;
    plan.value_count += plan.lines[plan.lines_of[i]].samples;
  }
  for (std::size_t li = 0; li < plan.lines.size(); ++li) {
    plan.base.push_back(plan.buffer_size);
    plan.buffer_size += plan.lines[li].samples * std::size_t(plan.stride[li]);
  }
  return plan;
}

void lsao_line_samples(const LsaoPlan& plan, const float* depth, LsaoSampling sampling,
                       int lines_index, int line_index, std::vector<LsaoSample>& out) {
  const LsaoLines& lines = plan.lines[lines_index];
  const SweepDirection& d = plan.directions[lines.direction];
  const LsaoLine& line = lines.lines[line_index];
  const int w = plan.width, h = plan.height;
  out.clear();
  float previous = kNaN;  // depth of the line's previous geometry sample
  for (int j = line.first; j < line.first + line.count; ++j) {
    double x, y;
    lsao_sample_position(line, d, j, x, y);
    const int tx = int(floor_ll(x)), ty = int(floor_ll(y));
    // Snapping (§5.2, as [BSD08]): the containing texel's centre and depth.
    LsaoSample sample{float(tx) + 0.5f, float(ty) + 0.5f, depth[std::size_t(ty) * w + tx]};
    const bool on_centre = x == tx + 0.5 && y == ty + 0.5;
    if (sampling == LsaoSampling::Interpolate && !on_centre) {
      // Bilinear between the four surrounding texel centres (clamped at the border), unless
      // one is background or the result jumps from the previous sample: an edge (§5.2).
      const double gx = x - 0.5, gy = y - 0.5;
      const int x0 = int(floor_ll(gx)), y0 = int(floor_ll(gy));
      const float fx = float(gx - x0), fy = float(gy - y0);
      auto at = [&](int xi, int yi) {
        xi = std::clamp(xi, 0, w - 1), yi = std::clamp(yi, 0, h - 1);
        return depth[std::size_t(yi) * w + xi];
      };
      const float d00 = at(x0, y0), d10 = at(x0 + 1, y0), d01 = at(x0, y0 + 1),
                  d11 = at(x0 + 1, y0 + 1);
      // a + t·(b − a): equal depths interpolate to themselves exactly, so a plane of
      // constant depth stays exactly level.
      const float top = d00 + fx * (d10 - d00), bottom = d01 + fx * (d11 - d01);
      const float di = top + fy * (bottom - top);
      const bool edge = previous == previous &&
                        std::abs(di - previous) > kLsaoEdgeRelativeDepth * std::min(di, previous);
      if (di == di && !edge) sample = {float(x), float(y), di};  // NaN if any tap is background
    }
    out.push_back(sample);
    if (sample.depth == sample.depth) previous = sample.depth;
  }
}

LsaoTexelRecord* LsaoRecordArena::take(std::size_t n) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (chunks_.empty() || chunks_.back().size() - used_ < n) {
    chunks_.emplace_back(std::max(n, kLsaoRecordChunk));
    used_ = 0;
  }
  LsaoTexelRecord* out = chunks_.back().data() + used_;
  used_ += n;
  return out;
}

LsaoSweep lsao_sweep(const GBuffer& g, const LsaoSettings& s, const RunOptions& options) {
  g.validate();
  LsaoSweep sweep;
  sweep.plan = lsao_plan(g, s);
  const LsaoPlan& plan = sweep.plan;
  const int threads = resolve_threads(options.threads);
  const Buffer<float> depth = depth_with_background_as_nan(g, threads);
  const LsaoTangent strategy = LsaoTangent(s.tangent_strategy);
  Image normals;
  if (strategy != LsaoTangent::Fixed) normals = prepared_normals(g, threads);
  const double radius = s.radius;
  const Context c{plan,
                  s,
                  normals.data(),
                  float(1.0 / (double(kLsaoFalloffOffset) * radius * radius)),
                  LsaoFalloff(s.falloff),
                  strategy,
                  LsaoSampling(s.sampling)};

  sweep.buffer.assign(plan.buffer_size, kNaN);
  // One task per line: it samples the line once and sweeps it in each direction that uses
  // it. Every task writes its own part of the buffers, so the result does not depend on
  // which thread runs it.
  std::vector<std::vector<int>> directions_of(plan.lines.size());
  for (int k = 0; k < int(plan.directions.size()); ++k)
    directions_of[plan.lines_of[k]].push_back(k);
  std::vector<std::pair<int, int>> tasks;
  for (int li = 0; li < int(plan.lines.size()); ++li)
    for (int l = 0; l < int(plan.lines[li].lines.size()); ++l)
      if (plan.lines[li].lines[l].count > 0) tasks.emplace_back(li, l);

  if (options.progress) options.progress->total += std::int64_t(tasks.size());
  parallel_for_rows(
      int(tasks.size()), threads,
      [&](int t0, int t1) {
        std::vector<LsaoSample> samples;
        std::vector<HullPoint> hull;
        for (int t = t0; t < t1; ++t) {
          const auto [li, l] = tasks[t];
          const LsaoLine& line = plan.lines[li].lines[l];
          lsao_line_samples(plan, depth.data(), c.sampling, li, l, samples);
          const std::size_t stride = std::size_t(plan.stride[li]);
          float* records = sweep.buffer.data() + plan.depth_index(li, line.offset);
          for (std::size_t i = 0; i < samples.size(); ++i) records[i * stride] = samples[i].depth;
          for (int k : directions_of[li]) {
            const Slice slice = make_slice(plan, k, line);
            sweep_line(c, slice, samples, plan.reversed[k], records + plan.slot[k], stride, hull);
          }
        }
      },
      options.progress);
  return sweep;
}

Image lsao_gather(const GBuffer& g, const LsaoSettings& s, const LsaoSweep& sweep,
                  const RunOptions& options) {
  const LsaoPlan& plan = sweep.plan;
  CHECK_EQ(plan.width, g.width());
  CHECK_EQ(plan.height, g.height());
  const int w = g.width(), h = g.height();
  const int threads = resolve_threads(options.threads);
  const Buffer<float> depth = depth_with_background_as_nan(g, threads);
  Image normals;
  if (s.normal_aware_gather) normals = prepared_normals(g, threads);
  const std::vector<GatherAxis> axes = gather_axes(plan, s.line_spacing);
  const GatherInputs in{plan,
                        sweep,
                        axes,
                        depth.data(),
                        normals.data(),
                        s.normal_aware_gather,
                        s.gather_depth_tolerance,
                        LsaoSampling(s.sampling) == LsaoSampling::Interpolate,
                        w,
                        h};

  Image out(w, h, 1, 1.0f);
  const int bands = (h + kGatherRows - 1) / kGatherRows;
  if (options.progress) options.progress->total += bands;
  parallel_for_rows(
      bands, threads,
      [&](int b0, int b1) {
        GatherBand band(in);
        for (int b = b0; b < b1; ++b) band.run(b, out);
      },
      options.progress);
  return out;
}

Image lsao(const GBuffer& g, const LsaoSettings& s, const RunOptions& options) {
  if (options.kernel == Kernel::Simd) return lsao_simd_kernel(g, s, options);
  const LsaoSweep sweep = lsao_sweep(g, s, options);
  return lsao_gather(g, s, sweep, options);
}

Method lsao_method() {
  Method m = registered_method("lsao", "Line-sweep ambient obscurance",
                               "Timonen 2013, Line-Sweep Ambient Obscuration", kLsaoFields, lsao);
  m.has_simd_kernel = true;
  return m;
}

}  // namespace aolab
