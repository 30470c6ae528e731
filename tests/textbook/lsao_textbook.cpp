#include "tests/textbook/lsao_textbook.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <limits>
#include <vector>

namespace aolab {

namespace {

using dvec2 = glm::dvec2;
using dvec3 = glm::dvec3;

dvec3 position(const CameraIntrinsics& c, double px, double py, double d) {
  return {(px - c.cx) / c.fx * d, -(py - c.cy) / c.fy * d, -d};
}

// The plane through the eye and a line, built from two of its view rays: b1 along the line
// (horizontal in view space), bz the in-plane unit vector perpendicular to it on the camera
// side (+z). A view-space point is moved onto the plane horizontally, across the line (at
// constant depth), and has the 2-D coordinates (X'·b1, X'·bz). Points of the line are
// already on the plane; snapped samples just off it keep their depth.
struct Plane {
  dvec3 b1, bz, m, across;
  dvec2 project(const dvec3& x) const {
    const dvec3 on = x - glm::dot(x, m) / glm::dot(across, m) * across;
    return {glm::dot(on, b1), glm::dot(on, bz)};
  }
};

Plane sweep_plane(const CameraIntrinsics& cam, const LsaoLine& line, const SweepDirection& d) {
  const dvec3 r0 = position(cam, line.origin_x, line.origin_y, 1.0);
  const dvec3 r1 = position(cam, line.origin_x + d.step_x, line.origin_y + d.step_y, 1.0);
  Plane p;
  p.b1 = glm::normalize(r1 - r0);  // z of both is −1: horizontal
  p.m = glm::normalize(glm::cross(r0, r1));
  p.bz = glm::normalize(glm::cross(p.m, p.b1));
  if (p.bz.z < 0) p.bz = -p.bz;
  p.across = dvec3(-p.b1.y, p.b1.x, 0.0);
  return p;
}

double falloff(double d2, double r, LsaoFalloff f) {
  // The reference's cut-off: 1 for d ≤ R, i.e. d² ≤ r/C (r = C·R²), 0 beyond.
  if (f == LsaoFalloff::Cutoff) return d2 <= r / double(kLsaoFalloffOffset) ? 1.0 : 0.0;
  const double rho = r / (r + d2);  // eq. 2
  if (f == LsaoFalloff::Eq2) return rho;
  const double c = kLsaoFalloffOffset;
  return std::max(0.0, r * (1.0 + c) / (r + d2) - c);  // eq. 3
}

// sin t of the receiver's tangent in the half-plane of the earlier samples: the tangent
// direction of the projected normal n2 on that side, as an elevation from û. If n2 faces
// away from the eye in the plane, the limit of a normal turning to face it.
double tangent_sin(const dvec2& n2, const dvec2& u, double fixed) {
  const dvec2 e(-u.y, u.x);  // perpendicular to û, towards decreasing a (the earlier samples)
  const double ne = glm::dot(n2, e), nu = glm::dot(n2, u);
  if (ne == 0.0 && nu <= 0.0) return fixed;  // no tangent within the plane
  if (nu <= 0.0) return ne > 0.0 ? -1.0 : 1.0;
  dvec2 t(-n2.y, n2.x);  // perpendicular to n2
  if (glm::dot(t, e) < 0.0) t = -t;
  return glm::dot(glm::normalize(t), u);
}

}  // namespace

LsaoSweep lsao_textbook_sweep(const GBuffer& g, const LsaoSettings& s) {
  LsaoSweep sweep;
  sweep.plan = lsao_plan(g, s);
  const LsaoPlan& plan = sweep.plan;
  const CameraIntrinsics& cam = g.camera;
  const Buffer<float> depth = depth_with_background_as_nan(g);
  const LsaoTangent strategy = LsaoTangent(s.tangent_strategy);
  const Image normals = prepared_normals(g, 1);
  const double r = double(kLsaoFalloffOffset) * double(s.radius) * double(s.radius);
  const double fixed = s.tangent_sin;
  sweep.buffer.assign(plan.buffer_size, std::numeric_limits<float>::quiet_NaN());

  std::vector<LsaoSample> samples;
  for (int k = 0; k < int(plan.directions.size()); ++k) {
    const int li = plan.lines_of[k];
    const LsaoLines& lines = plan.lines[li];
    for (int l = 0; l < int(lines.lines.size()); ++l) {
      const LsaoLine& line = lines.lines[l];
      if (line.count == 0) continue;
      lsao_line_samples(plan, depth.data(), LsaoSampling(s.sampling), li, l, samples);
      const int n = int(samples.size());
      for (int i = 0; i < n; ++i)
        sweep.buffer[plan.depth_index(li, line.offset + i)] = samples[i].depth;
      // Sweep order and the plane with b1 along this direction's own motion.
      std::vector<int> order(n);
      for (int i = 0; i < n; ++i) order[i] = plan.reversed[k] ? n - 1 - i : i;
      const SweepDirection& own = plan.directions[k];
      const Plane plane = sweep_plane(cam, line, own);
      std::vector<dvec2> pts(n);
      for (int i = 0; i < n; ++i)
        pts[i] = plane.project(position(cam, samples[i].x, samples[i].y, samples[i].depth));

      for (int a = 0; a < n; ++a) {
        const int i = order[a];
        if (!(samples[i].depth == samples[i].depth)) continue;  // background: NaN
        const dvec2 p = pts[i];
        const dvec2 u = -p / glm::length(p);  // Algorithm 1, line 7
        double t_hull = fixed, t_obscurance = fixed;
        if (strategy != LsaoTangent::Fixed) {
          const int tx = int(std::floor(samples[i].x)), ty = int(std::floor(samples[i].y));
          const dvec3 n3(normals(tx, ty, 0), normals(tx, ty, 1), normals(tx, ty, 2));
          const dvec2 n2(glm::dot(n3, plane.b1), glm::dot(n3, plane.bz));
          t_obscurance = tangent_sin(n2, u, fixed);
          if (strategy == LsaoTangent::Real) t_hull = t_obscurance;
        }
        // Every earlier sample: the largest occluder by the hull's criterion.
        double best = -1.0, best_sin = 0.0, best_rho = 0.0;
        bool found = false;
        for (int b = 0; b < a; ++b) {
          const int q = order[b];
          if (!(samples[q].depth == samples[q].depth)) continue;  // background never occludes
          if (samples[q].x == samples[i].x && samples[q].y == samples[i].y) continue;  // p itself
          const dvec2 h = pts[q] - p;
          const double len = glm::length(h);
          const double sin_h = glm::dot(h, u) / len;
          const double rho = falloff(len * len, r, LsaoFalloff(s.falloff));
          const double crit = std::max(0.0, sin_h - t_hull) * rho;
          if (crit >= best) best = crit, best_sin = sin_h, best_rho = rho, found = true;
        }
        // Eq. 1 for one direction; no occluder: h = t.
        const double o =
            found ? t_obscurance + std::max(0.0, best_sin - t_obscurance) * best_rho : t_obscurance;
        sweep.buffer[plan.value_index(k, line.offset + i)] = float(o);
      }
    }
  }
  return sweep;
}

Image lsao_textbook_gather(const GBuffer& g, const LsaoSettings& s, const LsaoSweep& sweep) {
  const LsaoPlan& plan = sweep.plan;
  const int w = g.width(), h = g.height();
  const Buffer<float> depth = depth_with_background_as_nan(g);
  const Image normals = prepared_normals(g, 1);
  const bool interpolated = LsaoSampling(s.sampling) == LsaoSampling::Interpolate;
  Image out(w, h, 1, 1.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double dp = depth[std::size_t(y) * w + x];
      if (!(dp == dp)) continue;
      const double px = x + 0.5, py = y + 0.5;
      double sum = 0.0, weights = 0.0;
      for (int pass = 0; pass < 2 && weights == 0.0; ++pass)
        for (int k = 0; k < int(plan.directions.size()); ++k) {
          const int li = plan.lines_of[k];
          const LsaoLines& lines = plan.lines[li];
          const SweepDirection& d = plan.directions[lines.direction];
          const double radius = lsao_gather_radius(d, s.line_spacing);
          double best = std::numeric_limits<double>::infinity();
          double value = 0.0;
          bool found = false;
          for (const LsaoLine& line : lines.lines)
            for (int j = line.first; j < line.first + line.count; ++j) {
              double sx, sy;
              lsao_sample_position(line, d, j, sx, sy);
              if (!interpolated) sx = std::floor(sx) + 0.5, sy = std::floor(sy) + 0.5;
              const double dist2 = (sx - px) * (sx - px) + (sy - py) * (sy - py);
              const std::size_t i = line.offset + std::size_t(j - line.first);
              const double v = sweep.value(k, i);
              const double dq = sweep.depth(li, i);
              if (!(v == v) || !(dist2 < best) || dist2 > radius * radius) continue;
              if (pass == 0) {
                if (!(std::abs(dq - dp) <= double(s.gather_depth_tolerance) * dp)) continue;
                if (s.normal_aware_gather) {
                  const int qx = int(std::floor(sx)), qy = int(std::floor(sy));
                  double dot = 0;
                  for (int c = 0; c < 3; ++c) dot += double(normals(x, y, c)) * normals(qx, qy, c);
                  if (!(dot >= double(kLsaoGatherNormalCos))) continue;
                }
              }
              best = dist2, value = v, found = true;
            }
          if (found) sum += plan.directions[k].weight * value, weights += plan.directions[k].weight;
        }
      if (weights > 0.0) out(x, y) = float(std::clamp(1.0 - sum / weights, 0.0, 1.0));
    }
  return out;
}

Image lsao_textbook(const GBuffer& g, const LsaoSettings& s) {
  return lsao_gather(g, s, lsao_textbook_sweep(g, s));
}

}  // namespace aolab
