#include "core/base/gbuffer.h"

#include <glm/geometric.hpp>
#include <limits>

#include "core/base/check.h"
#include "core/base/parallel.h"

namespace aolab {

void GBuffer::validate() const {
  if (depth.empty())
    throw_invalid(
        "depth", "must be a non-empty image (height and width >= 1)",
        "height " + std::to_string(depth.height) + ", width " + std::to_string(depth.width));
  if (depth.channels != 1) throw_invalid("depth", "must have 1 channel", depth.channels);
  if (!normal.empty()) {
    if (normal.channels != 3)
      throw_invalid("normal", "must have 3 channels (H, W, 3)", normal.channels);
    require_same_size("depth", depth, "normal", normal);
  }
  if (!color.empty()) {
    if (color.channels != 3 && color.channels != 4)
      throw_invalid("color", "must have 3 or 4 channels (H, W, 3|4)", color.channels);
    require_same_size("depth", depth, "color", color);
  }
  if (!emission.empty()) {
    if (emission.channels != 3 && emission.channels != 4)
      throw_invalid("emission", "must have 3 or 4 channels (H, W, 3|4)", emission.channels);
    require_same_size("depth", depth, "emission", emission);
  }
  camera.validate();
  if (!(background_depth > 0.0f))
    throw_invalid("background_depth", "must be > 0", background_depth);
}

void require_normal(const GBuffer& g, const std::string& method) {
  if (!g.has_normal())
    throw_invalid("normal",
                  "is required by " + method +
                      ", which reads view-space normals "
                      "(estimate them from depth with GBuffer.prepared_normals())",
                  "none");
}

void require_color(const GBuffer& g, const std::string& method, const std::string& setting) {
  if (!g.has_color())
    throw_invalid("color",
                  "is required by " + method + (setting.empty() ? "" : " with " + setting + " on"),
                  "none");
}

Image validity_mask(const GBuffer& g) {
  Image mask(g.width(), g.height(), 1);
  for (int y = 0; y < g.height(); ++y)
    for (int x = 0; x < g.width(); ++x) mask(x, y) = g.valid(x, y) ? 1.0f : 0.0f;
  return mask;
}

Image view_positions(const GBuffer& g, int threads) {
  Image p(g.width(), g.height(), 3);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  parallel_for_rows(g.height(), threads, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < g.width(); ++x) {
        const glm::vec3 v =
            g.valid(x, y) ? g.camera.view_position(float(x) + 0.5f, float(y) + 0.5f, g.depth(x, y))
                          : glm::vec3(nan);
        for (int c = 0; c < 3; ++c) p(x, y, c) = v[c];
      }
  });
  return p;
}

Buffer<float> depth_with_background_as_nan(const GBuffer& g, int threads) {
  const int w = g.width();
  Buffer<float> depth(std::size_t(w) * std::size_t(g.height()));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  parallel_for_rows(g.height(), threads, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w; ++x)
        depth[std::size_t(y) * w + x] = g.valid(x, y) ? g.depth(x, y) : nan;
  });
  return depth;
}

namespace {

glm::vec3 position_at(const GBuffer& g, int x, int y) {
  return g.camera.view_position(float(x) + 0.5f, float(y) + 0.5f, g.depth(x, y));
}

// The smaller of the one-sided differences towards valid neighbours along (dx, dy);
// false if neither neighbour is valid.
bool smaller_difference(const GBuffer& g, int x, int y, int dx, int dy, const glm::vec3& p,
                        glm::vec3& out) {
  bool found = false;
  float best = std::numeric_limits<float>::infinity();
  for (int s : {-1, 1}) {
    const int nx = x + s * dx, ny = y + s * dy;
    if (nx < 0 || ny < 0 || nx >= g.width() || ny >= g.height() || !g.valid(nx, ny)) continue;
    const glm::vec3 d = (position_at(g, nx, ny) - p) * float(s);
    const float len2 = glm::dot(d, d);
    if (len2 < best) best = len2, out = d, found = true;
  }
  return found;
}

}  // namespace

glm::vec3 normal_from_depth(const GBuffer& g, int x, int y) {
  const glm::vec3 p = position_at(g, x, y);
  const glm::vec3 to_camera = glm::normalize(-p);
  glm::vec3 ddx, ddy;
  if (smaller_difference(g, x, y, 1, 0, p, ddx) && smaller_difference(g, x, y, 0, 1, p, ddy)) {
    // Rows go down the image, so +y in pixels is -y in view space: ddx x ddy points away
    // from the camera; the facing test below settles the sign either way.
    glm::vec3 n = glm::cross(ddx, ddy);
    const float len = glm::length(n);
    if (std::isfinite(len) && len > 0.0f) {
      n /= len;
      return glm::dot(n, to_camera) < 0.0f ? -n : n;
    }
  }
  return to_camera;
}

glm::vec3 prepared_normal(const GBuffer& g, int x, int y) {
  if (!g.valid(x, y)) return glm::vec3(0.0f);
  if (g.has_normal()) {
    glm::vec3 n(g.normal(x, y, 0), g.normal(x, y, 1), g.normal(x, y, 2));
    const float len = glm::length(n);
    if (std::isfinite(len) && len >= kMinNormalLength) {
      n /= len;
      return glm::dot(n, -position_at(g, x, y)) < 0.0f ? -n : n;
    }
  }
  return normal_from_depth(g, x, y);
}

Image prepared_normals(const GBuffer& g, int threads) {
  Image out(g.width(), g.height(), 3, 0.0f);
  parallel_for_rows(g.height(), threads, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) prepared_normals_row(g, y, &out(0, y));
  });
  return out;
}

}  // namespace aolab
