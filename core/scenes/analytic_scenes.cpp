#include "core/scenes/analytic_scenes.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>
#include <map>
#include <numbers>

#include "core/base/check.h"

namespace aolab {

double cycles_ao_beside_wall(double distance, double radius) {
  const double a = distance / radius;
  if (a >= 1.0) return 1.0;
  return 1.0 - (std::acos(a) - a * std::sqrt(1.0 - a * a)) / std::numbers::pi;
}

double cycles_ao_under_ceiling(double height, double radius) {
  return radius > height ? (height / radius) * (height / radius) : 1.0;
}

AnalyticGBuffer render_analytic_scene(const AnalyticScene& scene, int width, int height,
                                      double radius) {
  if (width < 1) throw_invalid("width", "must be >= 1", width);
  if (height < 1) throw_invalid("height", "must be >= 1", height);
  if (!(scene.fov_deg > 0 && scene.fov_deg < 180))
    throw_invalid("fov", "must be in (0, 180) degrees", scene.fov_deg);
  if (!(radius > 0)) throw_invalid("radius", "must be > 0", radius);

  AnalyticGBuffer out;
  out.depth = Image(width, height, 1, kAnalyticBackgroundDepth);
  out.normal = Image(width, height, 3, 0.0f);
  out.reference = Image(width, height, 1, 1.0f);
  const double f = 0.5 * width / std::tan(0.5 * scene.fov_deg * std::numbers::pi / 180.0);
  out.camera = {float(f), float(f), 0.5f * float(width), 0.5f * float(height)};

  // Camera basis: looks down -z_cam towards the target, y_cam up.
  const glm::dvec3 back = glm::normalize(scene.eye - scene.target);
  const glm::dvec3 right = glm::normalize(glm::cross(scene.up, back));
  const glm::dvec3 up = glm::cross(back, right);
  out.camera_to_world = glm::dmat4(glm::dvec4(right, 0), glm::dvec4(up, 0), glm::dvec4(back, 0),
                                   glm::dvec4(scene.eye, 1));

  const double cx = 0.5 * width, cy = 0.5 * height;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      // View-space ray through the pixel centre with view z = -1, so hit distance t = depth.
      const glm::dvec3 dv((x + 0.5 - cx) / f, -(y + 0.5 - cy) / f, -1.0);
      const glm::dvec3 dw = dv.x * right + dv.y * up + dv.z * back;
      double best = std::numeric_limits<double>::infinity();
      const AnalyticFace* hit = nullptr;
      for (const auto& face : scene.faces) {
        const double denom = glm::dot(face.normal, dw);
        if (denom == 0.0) continue;
        const double t = (face.offset - glm::dot(face.normal, scene.eye)) / denom;
        if (!(t > 0.0) || t >= best) continue;
        const glm::dvec3 p = scene.eye + t * dw;
        bool inside = true;
        for (const auto& c : face.clips)
          if (glm::dot(glm::dvec3(c), p) > c.w + 1e-12 * (1.0 + std::abs(c.w))) inside = false;
        if (inside) best = t, hit = &face;
      }
      if (!hit || !(best < kAnalyticBackgroundDepth)) continue;
      out.depth(x, y) = float(best);
      glm::dvec3 n(glm::dot(hit->normal, right), glm::dot(hit->normal, up),
                   glm::dot(hit->normal, back));
      n = glm::normalize(n);
      if (glm::dot(n, dv) > 0.0) n = -n;  // face the camera
      for (int c = 0; c < 3; ++c) out.normal(x, y, c) = float(n[c]);
      const glm::dvec3 p = scene.eye + best * dw;
      out.reference(x, y) = hit->cycles_ao ? float(hit->cycles_ao(p, radius))
                                           : std::numeric_limits<float>::quiet_NaN();
    }
  return out;
}

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

AnalyticFace face(glm::dvec3 normal, double offset, std::vector<glm::dvec4> clips = {}) {
  AnalyticFace f;
  f.normal = glm::normalize(normal);
  f.offset = offset / glm::length(normal);
  f.clips = std::move(clips);
  return f;
}

// The six faces of an axis-aligned box (world space).
void add_box(AnalyticScene& s, glm::dvec3 lo, glm::dvec3 hi) {
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      glm::dvec3 n(0.0);
      n[axis] = side ? 1.0 : -1.0;
      std::vector<glm::dvec4> clips;
      for (int other = 0; other < 3; ++other) {
        if (other == axis) continue;
        glm::dvec3 e(0.0);
        e[other] = 1.0;
        clips.emplace_back(e, hi[other]);
        clips.emplace_back(-e, -lo[other]);
      }
      s.faces.push_back(face(n, side ? hi[axis] : -lo[axis], clips));
    }
}

using Params = std::map<std::string, double>;

// Merges user params into defaults, rejecting unknown names.
Params merge(const std::string& scene, Params defaults, const SettingValues& given) {
  defaults.emplace("radius", 1.0);
  for (const auto& [k, v] : given) {
    auto it = defaults.find(k);
    if (it == defaults.end()) {
      std::string valid;
      for (const auto& d : defaults) valid += (valid.empty() ? "" : ", ") + d.first;
      throw std::invalid_argument("unknown parameter '" + k + "' for analytic scene " + scene +
                                  "; valid: " + valid);
    }
    if (!std::isfinite(v)) throw_invalid(k, "must be finite", v);
    it->second = v;
  }
  return defaults;
}

AnalyticScene plane_scene(const Params& p) {
  // A plane through (0, 0, -distance) (world = view space), its normal tilted from the view
  // axis by `tilt` degrees towards azimuth `azimuth`. Unoccluded: Cycles AO = 1.
  AnalyticScene s;
  const double tilt = p.at("tilt") * kDeg, az = p.at("azimuth") * kDeg;
  if (!(std::abs(p.at("tilt")) < 90))
    throw_invalid("tilt", "must be in (-90, 90) degrees", p.at("tilt"));
  if (!(p.at("distance") > 0)) throw_invalid("distance", "must be > 0", p.at("distance"));
  const glm::dvec3 n(std::sin(tilt) * std::sin(az), std::sin(tilt) * std::cos(az), std::cos(tilt));
  AnalyticFace f = face(n, glm::dot(n, glm::dvec3(0, 0, -p.at("distance"))));
  f.cycles_ao = [](const glm::dvec3&, double) { return 1.0; };
  s.faces.push_back(f);
  s.fov_deg = p.at("fov");
  return s;
}

AnalyticScene ceiling_scene(const Params& p) {
  // Floor z = 0 under a parallel ceiling z = ceiling_height (both infinite), seen from half height
  // looking along +y: every point has Cycles AO (h/R)² for R > h.
  AnalyticScene s;
  const double h = p.at("ceiling_height");
  if (!(h > 0)) throw_invalid("ceiling_height", "must be > 0", h);
  auto ao = [h](const glm::dvec3&, double r) { return cycles_ao_under_ceiling(h, r); };
  AnalyticFace floor = face({0, 0, 1}, 0), ceiling = face({0, 0, -1}, -h);
  floor.cycles_ao = ceiling.cycles_ao = ao;
  s.faces = {floor, ceiling};
  s.eye = {0, 0, 0.5 * h};
  s.target = {0, 1, 0.5 * h};
  s.up = {0, 0, 1};
  s.fov_deg = p.at("fov");
  return s;
}

AnalyticScene wall_scene(const Params& p) {
  // Floor z = 0 (y <= distance) meeting a wall y = distance (z >= 0) in a crease, seen from
  // (0, 0, camera_height) looking at the foot of the wall.
  AnalyticScene s;
  const double wy = p.at("distance");
  if (!(wy > 0)) throw_invalid("distance", "must be > 0", wy);
  AnalyticFace floor = face({0, 0, 1}, 0, {{0, 1, 0, wy}});
  AnalyticFace wall = face({0, -1, 0}, -wy, {{0, 0, -1, 0}});
  floor.cycles_ao = [wy](const glm::dvec3& q, double r) {
    return cycles_ao_beside_wall(wy - q.y, r);
  };
  wall.cycles_ao = [](const glm::dvec3& q, double r) { return cycles_ao_beside_wall(q.z, r); };
  s.faces = {floor, wall};
  if (!(p.at("camera_height") > 0))
    throw_invalid("camera_height", "must be > 0", p.at("camera_height"));
  s.eye = {0, 0, p.at("camera_height")};
  s.target = {0, wy, 0};
  s.up = {0, 0, 1};
  s.fov_deg = p.at("fov");
  return s;
}

AnalyticScene crease_scene(const Params& p) {
  // A concave V of two perpendicular planes whose crease is the line y = 0, z = -distance,
  // seen head-on from the origin (world = view space); each plane faces the camera at 45°.
  AnalyticScene s;
  const double d = p.at("distance");
  if (!(d > 0)) throw_invalid("distance", "must be > 0", d);
  // Distance from the crease line within either plane: sqrt(y² + (z + d)²).
  auto ao = [d](const glm::dvec3& q, double r) {
    return cycles_ao_beside_wall(std::hypot(q.y, q.z + d), r);
  };
  AnalyticFace lower = face({0, 1, 1}, -d, {{0, 1, 0, 0}});
  AnalyticFace upper = face({0, -1, 1}, -d, {{0, -1, 0, 0}});
  lower.cycles_ao = upper.cycles_ao = ao;
  s.faces = {lower, upper};
  s.fov_deg = p.at("fov");
  return s;
}

AnalyticScene step_scene(const Params& p) {
  // A floor facing the camera at depth `distance` and, for x >= 0, a raised slab whose top is
  // `step_height` closer; its side lies in the plane x = 0, edge-on to the camera, so the depth
  // buffer shows a clean step. A narrow field of view keeps it close to a heightfield seen
  // from straight above (HBAO's known answer is integrated numerically in the tests).
  AnalyticScene s;
  const double d = p.at("distance"), h = p.at("step_height");
  if (!(d > 0)) throw_invalid("distance", "must be > 0", d);
  if (!(h > 0 && h < d)) throw_invalid("step_height", "must be in (0, distance)", h);
  s.faces.push_back(face({0, 0, 1}, -d, {{1, 0, 0, 0}}));
  s.faces.push_back(face({0, 0, 1}, -(d - h), {{-1, 0, 0, 0}}));
  s.faces.push_back(face({-1, 0, 0}, 0, {{0, 0, 1, -(d - h)}, {0, 0, -1, d}}));
  s.fov_deg = p.at("fov");
  return s;
}

AnalyticScene blocks_scene(const Params& p) {
  // A floor with a deterministic arrangement of boxes, seen obliquely from above: creases,
  // contact regions, depth edges and grazing floor at the horizon. For benchmarks and demos.
  AnalyticScene s;
  s.faces.push_back(face({0, 0, 1}, 0));
  const double size = p.at("size");
  if (!(size > 0)) throw_invalid("size", "must be > 0", size);
  add_box(s, glm::dvec3(-1.5, 2.0, 0) * size, glm::dvec3(-0.5, 3.0, 1.0) * size);
  add_box(s, glm::dvec3(0.2, 3.5, 0) * size, glm::dvec3(1.4, 4.2, 2.0) * size);
  add_box(s, glm::dvec3(-0.3, 1.0, 0) * size, glm::dvec3(0.3, 1.6, 0.3) * size);
  add_box(s, glm::dvec3(1.6, 1.5, 0) * size, glm::dvec3(2.4, 2.3, 0.6) * size);
  add_box(s, glm::dvec3(-3.0, 5.0, 0) * size, glm::dvec3(3.0, 5.4, 2.5) * size);     // back wall
  add_box(s, glm::dvec3(-2.6, 3.6, 0.9) * size, glm::dvec3(-1.2, 4.4, 1.1) * size);  // shelf
  s.eye = glm::dvec3(0, -2.0, 2.2) * size;
  s.target = glm::dvec3(0, 3.0, 0.2) * size;
  s.up = {0, 0, 1};
  s.fov_deg = p.at("fov");
  return s;
}

struct SceneEntry {
  const char* name;
  Params defaults;
  AnalyticScene (*build)(const Params&);
};

const std::vector<SceneEntry>& scene_table() {
  static const std::vector<SceneEntry> table = {
      {"plane", {{"distance", 5}, {"tilt", 0}, {"azimuth", 0}, {"fov", 60}}, plane_scene},
      {"ceiling", {{"ceiling_height", 1}, {"fov", 90}}, ceiling_scene},
      {"wall", {{"distance", 3}, {"camera_height", 1.5}, {"fov", 70}}, wall_scene},
      {"crease", {{"distance", 5}, {"fov", 60}}, crease_scene},
      {"step", {{"distance", 50}, {"step_height", 0.5}, {"fov", 10}}, step_scene},
      {"blocks", {{"size", 1}, {"fov", 70}}, blocks_scene},
  };
  return table;
}

}  // namespace

std::vector<std::string> analytic_scene_names() {
  std::vector<std::string> names;
  for (const auto& e : scene_table()) names.emplace_back(e.name);
  return names;
}

namespace {

// The scene table's entry for `name`, or std::invalid_argument listing the names.
const SceneEntry& scene_entry(const std::string& name) {
  for (const auto& e : scene_table())
    if (name == e.name) return e;
  std::string names;
  for (const auto& n : analytic_scene_names()) names += (names.empty() ? "" : ", ") + n;
  throw_invalid("scene", "must be one of " + names, "'" + name + "'");
}

}  // namespace

AnalyticGBuffer analytic_scene(const std::string& name, int width, int height,
                               const SettingValues& params) {
  const SceneEntry& e = scene_entry(name);
  const Params p = merge(name, e.defaults, params);
  return render_analytic_scene(e.build(p), width, height, p.at("radius"));
}

AnalyticScene analytic_scene_geometry(const std::string& name, const SettingValues& params) {
  const SceneEntry& e = scene_entry(name);
  return e.build(merge(name, e.defaults, params));
}

TriangleMesh analytic_scene_mesh(const AnalyticScene& scene, double extent) {
  if (!(extent > 0 && std::isfinite(extent))) throw_invalid("extent", "must be > 0", extent);
  TriangleMesh mesh;
  for (const AnalyticFace& f : scene.faces) {
    // Two unit vectors spanning the plane, and the plane's point nearest the camera.
    const glm::dvec3 n = f.normal;
    const glm::dvec3 helper = std::abs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    const glm::dvec3 u = glm::normalize(glm::cross(n, helper)), v = glm::cross(n, u);
    const glm::dvec3 centre = scene.eye - (glm::dot(n, scene.eye) - f.offset) * n;
    std::vector<glm::dvec3> poly = {
        centre - extent * u - extent * v, centre + extent * u - extent * v,
        centre + extent * u + extent * v, centre - extent * u + extent * v};
    for (const glm::dvec4& c : f.clips) {  // keep dot(c.xyz, X) <= c.w
      std::vector<glm::dvec3> kept;
      const glm::dvec3 cn(c);
      for (std::size_t i = 0; i < poly.size(); ++i) {
        const glm::dvec3 &a = poly[i], &b = poly[(i + 1) % poly.size()];
        const double da = glm::dot(cn, a) - c.w, db = glm::dot(cn, b) - c.w;
        if (da <= 0) kept.push_back(a);
        if ((da < 0 && db > 0) || (da > 0 && db < 0))
          kept.push_back(a + (da / (da - db)) * (b - a));
      }
      poly = std::move(kept);
    }
    if (poly.size() < 3) continue;
    const auto first = std::uint32_t(mesh.vertex_count());
    for (const glm::dvec3& p : poly)
      for (int k = 0; k < 3; ++k) mesh.vertices.push_back(float(p[k]));
    for (std::uint32_t i = 1; i + 1 < poly.size(); ++i)
      mesh.triangles.insert(mesh.triangles.end(), {first, first + i, first + i + 1});
  }
  return mesh;
}

}  // namespace aolab
