#include "core/methods/bitmask/bitmask.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <numbers>
#include <vector>

#include "core/horizon/slice.h"
#include "core/methods/bitmask/bitmask_shared.h"

namespace aolab {
namespace {

constexpr double kHalfPi = std::numbers::pi / 2.0;

// Per-run tables of the sector edges and centres: with N sectors of equal angle over the
// hemisphere [n − π/2, n + π/2] of a slice, the 2N + 1 points φ_i = n − π/2 + iδ, δ = π/(2N)
// (even i: the N + 1 edges, odd i: the N centres). cos φ_i = sin n cos iδ + cos n sin iδ by the
// angle sum, so a slice needs no trigonometry beyond cos n and sin n.
struct SectorTables {
  int sectors;
  std::vector<double> cos_step, sin_step;  // cos iδ, sin iδ, i = 0 … 2N
  std::vector<double> cos_edge, sin_edge;  // cos 2jπ/N, sin 2jπ/N, j = 0 … N (for eq. 7)

  explicit SectorTables(int n) : sectors(n) {
    const double delta = std::numbers::pi / (2.0 * n);
    for (int i = 0; i <= 2 * n; ++i) {
      cos_step.push_back(std::cos(i * delta));
      sin_step.push_back(std::sin(i * delta));
    }
    for (int j = 0; j <= n; ++j) {
      cos_edge.push_back(std::cos(4.0 * j * delta));
      sin_edge.push_back(std::sin(4.0 * j * delta));
    }
  }
};

// One slice: GTAO's geometry (core/horizon/slice.h) and where its sector edges and centres lie.
struct Slice : SliceGeometry {
  // cos φ_i of the 2N + 1 points; the points with φ_i < 0 (i < first_side0) lie on side 1,
  // the others on side 0. Within a side the angle from v grows away from index first_side0.
  double cos_phi[2 * kBitmaskMaxSectors + 1];
  int first_side0;
};

void place_sectors(Slice& sl, const SectorTables& t) {
  const int points = 2 * t.sectors + 1;
  sl.first_side0 = points;
  for (int i = 0; i < points; ++i) {
    sl.cos_phi[i] = sl.sin_n * t.cos_step[i] + sl.cos_n * t.sin_step[i];
    const double phi = sl.n - kHalfPi + i * (std::numbers::pi / (2.0 * t.sectors));
    if (phi >= 0.0 && sl.first_side0 == points) sl.first_side0 = i;
  }
}

// pos(θ) = #{i : φ_i ≤ θ} for a sample at angle θ from v, given by its cosine c: on side 0
// (θ ≥ 0) every point of side 1 and those of side 0 with cos φ_i ≥ c; on side 1 (θ ≤ 0) the
// points of side 1 with cos φ_i ≤ c. Within a side the cosines are monotonic: a binary search,
// no acos per sample.
int point_count(const Slice& sl, int points, double c, int side) {
  if (side == 0) {
    const double* first = sl.cos_phi + sl.first_side0;
    return int(std::partition_point(first, sl.cos_phi + points, [c](double x) { return x >= c; }) -
               sl.cos_phi);
  }
  return int(std::partition_point(sl.cos_phi, sl.cos_phi + sl.first_side0,
                                  [c](double x) { return x <= c; }) -
             sl.cos_phi);
}

// The sectors [first, last) an interval of slice angles [a, b] marks, from pos(a) and pos(b)
// (points φ_i ≤ a and ≤ b): edges ≤ x are ⌈pos/2⌉, centres ≤ x are ⌊pos/2⌋.
std::uint64_t interval_bits(int pos_a, int pos_b, int sectors, BitmaskRounding rounding) {
  int first = 0, last = 0;
  switch (rounding) {
    case BitmaskRounding::Touch:  // from the sector holding a to the one holding b
      first = (pos_a + 1) / 2 - 1, last = (pos_b + 1) / 2;
      break;
    case BitmaskRounding::Half:  // the sectors whose centre lies in [a, b]
      first = pos_a / 2, last = pos_b / 2;
      break;
    case BitmaskRounding::Cover:  // the sectors whose both edges lie in [a, b]
      first = (pos_a + 1) / 2, last = (pos_b + 1) / 2 - 1;
      break;
  }
  first = std::max(first, 0);
  last = std::min(last, sectors);
  if (last <= first) return 0;
  const int width = last - first;
  const std::uint64_t ones = width >= 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << width) - 1;
  return ones << first;
}

// A(φ) = sgn(φ) · ¼(−cos(2φ − n) + cos n + 2φ sin n): the cosine-weighted slice integral
// ∫_0^φ cos(θ − n)|sin θ| dθ with its sign (GTAO's eq. 7, a(φ), is the unsigned one), so the
// measure of a sector is A at its upper edge minus A at its lower edge. At edge j,
// 2φ − n = n − π + 2jπ/N, so cos(2φ − n) = −(cos n cos 2jπ/N − sin n sin 2jπ/N).
void sector_weights(const Slice& sl, const SectorTables& t, double* weights) {
  double previous = 0.0;
  for (int j = 0; j <= t.sectors; ++j) {
    const double phi = sl.n - kHalfPi + j * (std::numbers::pi / t.sectors);
    const double cos_2phi_n = -(sl.cos_n * t.cos_edge[j] - sl.sin_n * t.sin_edge[j]);
    const double a = 0.25 * (-cos_2phi_n + sl.cos_n + 2.0 * phi * sl.sin_n);
    const double signed_a = phi < 0.0 ? -a : a;
    if (j > 0) weights[j - 1] = signed_a - previous;
    previous = signed_a;
  }
}

struct Params {
  const BitmaskSettings& s;
  BitmaskWeighting weighting;
  BitmaskRounding rounding;
  BitmaskRadiusClip clip;
  BitmaskBackDirection back;
  double thickness;  // T = thickness · R, view-space units
  double radius2;    // R²
  std::uint64_t full;
};

// The sectors one sample marks on `side`, or 0. The sample occupies the segment
// X(t) = D + t·u, t ∈ [0, T], from its front S to its back: u = −v (back_direction = view, the
// paper's Algorithm 1) or u = S/|S| (sample_ray, EEVEE's); with radius_clip = sphere the segment
// is clipped to |X| ≤ R first. Both ends are projected onto the slice plane and turned into
// cosines from v in double precision (T reaches 1e60); the sector search needs no acos.
std::uint64_t sample_bits(const HorizonReceiver& p, const Params& q, const Slice& sl,
                          const glm::vec3& v, int points, int sx, int sy, float ds, int side) {
  const float qx = float(sx - p.x), qy = float(sy - p.y);
  const glm::vec3 D = slice_sample_offset(p, qx, qy, ds);
  const float r2 = glm::dot(D, D);
  if (q.clip == BitmaskRadiusClip::Cut && !(double(r2) <= q.radius2)) return 0;
  if (!above_tangent_plane(p, qx, qy, ds)) return 0;
  const glm::dvec3 d(D), a(sl.axis), w(v);
  const glm::dvec3 u =
      q.back == BitmaskBackDirection::View
          ? -w
          : glm::normalize(glm::dvec3((p.ox + qx) * p.inv_fx, -(p.oy + qy) * p.inv_fy, -1.0));
  const double dv = glm::dot(d, w), uv = glm::dot(u, w), ad = glm::dot(a, d), au = glm::dot(a, u),
               du = glm::dot(d, u);
  double t0 = 0.0, t1 = q.thickness;
  if (q.clip == BitmaskRadiusClip::Sphere) {
    // |D + t u|² = R²: t² + 2(D·u)t + (|D|² − R²) = 0, roots without cancellation.
    const double c = double(r2) - q.radius2;
    const double disc = du * du - c;
    if (!(disc > 0.0)) return 0;
    const double root = -du - std::copysign(std::sqrt(disc), du);
    double lo = root, hi = c / root;
    if (lo > hi) std::swap(lo, hi);
    t0 = std::max(t0, lo);
    t1 = std::min(t1, hi);
    if (!(t1 >= t0)) return 0;
  }
  // cos θ(t) = (X·v) / |X − a(a·X)|, with |X − a(a·X)|² = |X|² − (a·X)² formed as the squared
  // distance of X from the line of a: exact for u = −v, where it is (D·v − t)² + e².
  const double e2 = std::max(0.0, double(r2) - ad * ad - dv * dv);
  const auto cos_at = [&](double t) {
    if (t == 0.0) return dv / std::sqrt(dv * dv + e2);
    const double along = dv + t * uv;
    const double off = ad + t * au;
    const double norm2 = q.back == BitmaskBackDirection::View
                             ? along * along + e2
                             : std::max(0.0, double(r2) + t * (2.0 * du + t) - off * off);
    return along / std::sqrt(norm2);
  };
  const double cos_front = cos_at(t0), cos_back = cos_at(t1);
  if (!(cos_front > cos_back)) return 0;  // an empty interval (T = 0), or no direction at all
  // Side 0: [a, b] = [θ_front, θ_back]; side 1: [−θ_back, −θ_front].
  const int pos_a = point_count(sl, points, side == 0 ? cos_front : cos_back, side);
  const int pos_b = point_count(sl, points, side == 0 ? cos_back : cos_front, side);
  return interval_bits(pos_a, pos_b, q.s.sectors, q.rounding);
}

float bitmask_pixel(const SliceFrame& f, const Params& q, const SectorTables& tables,
                    const HorizonDirections& directions, int x, int y, float* dir_cos,
                    float* dir_sin) {
  const BitmaskSettings& s = q.s;
  // GTAO's set-up and random streams: with the same settings both march the same samples.
  SlicePixel px;
  if (!slice_pixel(f, directions, x, y, s.seed, s.random_rotation, s.jitter, dir_cos, dir_sin, px))
    return 1.0f;  // background
  const HorizonReceiver& p = px.p;
  const glm::vec3& v = px.v;
  const float jitter = px.jitter;
  const int points = 2 * s.sectors + 1;
  double visible = 0.0, open = 0.0, mean = 0.0;
  double weights[kBitmaskMaxSectors];
  for (int k = 0; k < s.slices; ++k) {
    Slice sl;
    static_cast<SliceGeometry&>(sl) =
        make_slice_geometry(f.cam, s.radius, s.steps, p, v, dir_cos[k], dir_sin[k]);
    place_sectors(sl, tables);
    // The paper's Algorithm 1: one mask per slice, OR-ed by every sample of both sides.
    std::uint64_t mask = 0;
    for (int side = 0; side < 2 && mask != q.full; ++side)
      march_slice_side(f, p, sl, s.steps, jitter, side, [&](int sx, int sy, float ds) {
        mask |= sample_bits(p, q, sl, v, points, sx, sy, ds, side);
        return mask != q.full;  // every sector occluded: no sample can change the slice
      });
    double slice_visible = 0.0, slice_open = 0.0;
    if (q.weighting == BitmaskWeighting::Uniform) {
      // Algorithm 1: the fraction of free sectors, 1 − bitCount(b)/N.
      slice_visible = double(s.sectors - std::popcount(mask)) / double(s.sectors);
      slice_open = 1.0;
    } else {
      // Each sector weighted by its cosine-weighted measure; the free and the total sums run
      // in the same order, so an empty mask gives the same bits for both.
      sector_weights(sl, tables, weights);
      for (int j = 0; j < s.sectors; ++j) {
        slice_open += weights[j];
        if (!((mask >> j) & 1u)) slice_visible += weights[j];
      }
    }
    const double length = sl.length;  // eq. 8 of the memo: the projected normal's length
    visible += length * slice_visible;
    open += length * slice_open;
    mean += q.weighting == BitmaskWeighting::Uniform ? slice_visible : length * slice_visible;
  }
  double ao = 1.0;
  if (s.normalization == int(BitmaskNormalization::Slices))
    ao = mean / double(s.slices);
  else if (open > 0.0)
    ao = visible / open;
  return std::clamp(float(ao), 0.0f, 1.0f);
}

}  // namespace

Image bitmask(const GBuffer& g, const BitmaskSettings& s, const RunOptions& options) {
  g.validate();
  require_normal(g, "bitmask");
  validate_settings(s, kBitmaskFields);
  const Params params{s,
                      BitmaskWeighting(s.weighting),
                      BitmaskRounding(s.rounding),
                      BitmaskRadiusClip(s.radius_clip),
                      BitmaskBackDirection(s.back_direction),
                      double(s.thickness) * double(s.radius),
                      double(s.radius) * double(s.radius),
                      s.sectors >= 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << s.sectors) - 1};
  const SectorTables tables(s.sectors);
  return run_slice_method(
      g, s.slices, s.mip_distance, options,
      [&](const SliceFrame& f, const HorizonDirections& directions, int x, int y, float* dir_cos,
          float* dir_sin) {
        return bitmask_pixel(f, params, tables, directions, x, y, dir_cos, dir_sin);
      },
      [&](const SliceFrame& f, int threads, Progress* progress) {
        return bitmask_simd(f, s, threads, progress);
      });
}

Method bitmask_method() {
  Method m = registered_method(
      "bitmask", "Visibility bitmask ambient occlusion",
      "Therrien, Levesque, Gilet 2023, Screen Space Indirect Lighting with Visibility Bitmask",
      kBitmaskFields, bitmask);
  m.needs_normal = true;
  m.has_simd_kernel = true;
  return m;
}

}  // namespace aolab
