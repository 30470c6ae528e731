#include "core/methods/crytek_ssao/crytek_ssao.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/geometric.hpp>
#include <limits>
#include <numbers>
#include <vector>

#include "core/base/parallel.h"
#include "core/methods/crytek_ssao/crytek_ssao_shared.h"
#include "core/sampling/random.h"

namespace aolab {

namespace {

// Streams of pixel_random: the kernel and the tiled vectors are drawn at "pixels" (i, 0) of
// their own streams, so they depend on the seed alone.
constexpr std::uint32_t kKernelStream = 101;
constexpr std::uint32_t kTileStream = 202;
constexpr std::uint32_t kPixelStream = kCrytekSsaoPixelStream;

// A unit vector from two uniforms (uniform on the sphere: z uniform in [−1, 1]).
glm::vec3 unit_vector(float u1, float u2) {
  const float z = 2.0f * u1 - 1.0f;
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = 2.0f * std::numbers::pi_v<float> * u2;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

glm::vec3 random_unit(std::uint32_t seed, int i, int j, std::uint32_t stream) {
  return unit_vector(pixel_random(seed, i, j, stream), pixel_random(seed, i, j, stream + 1));
}

struct Frame {
  const float* depth;    // background replaced by NaN, so every comparison with it fails
  const float* normals;  // prepared, 3 per pixel; null unless the hemisphere variant
  int width, height;
  CameraIntrinsics cam;
};

float crytek_pixel(const Frame& f, const CrytekSsaoSettings& s,
                   const std::vector<glm::vec3>& kernel, const glm::vec3 (&tile)[16], int x,
                   int y) {
  const std::size_t idx = std::size_t(y) * f.width + x;
  const float d = f.depth[idx];
  if (!(d == d)) return 1.0f;  // background
  const glm::vec3 p = f.cam.view_position(float(x) + 0.5f, float(y) + 0.5f, d);
  glm::vec3 r(0.0f);
  switch (CrytekSsaoRotation(s.rotation)) {
    case CrytekSsaoRotation::Tiled4x4:
      r = tile[(x & 3) + 4 * (y & 3)];
      break;
    case CrytekSsaoRotation::PerPixel:
      r = random_unit(std::uint32_t(s.seed), x, y, kPixelStream);
      break;
    case CrytekSsaoRotation::None:
      break;
  }
  const bool hemisphere = f.normals != nullptr;
  const glm::vec3 n =
      hemisphere ? glm::vec3(f.normals[3 * idx], f.normals[3 * idx + 1], f.normals[3 * idx + 2])
                 : glm::vec3(0.0f);
  const float radius = s.radius;
  const auto range = CrytekSsaoRangeCheck(s.range_check);
  float occluded = 0.0f;
  for (const glm::vec3& k : kernel) {
    glm::vec3 o = k - 2.0f * glm::dot(k, r) * r;  // reflection: lengths and pairs kept
    if (hemisphere && glm::dot(o, n) < 0.0f) o = -o;
    const glm::vec3 sp = p + radius * o;
    if (!(sp.z < 0.0f)) continue;  // at or behind the camera plane: nothing in front of it
    const glm::vec3 q = f.cam.project(sp);
    // Off the image (or not finite): no depth to compare with, not occluded. Checked in
    // float before the conversion, which would overflow for far points.
    if (!(q.x >= 0.0f && q.x < float(f.width) && q.y >= 0.0f && q.y < float(f.height))) continue;
    const float stored = f.depth[std::size_t(q.y) * f.width + std::size_t(q.x)];
    const float delta = q.z - stored;  // > 0: the stored surface lies in front of the point
    if (!(delta > 0.0f)) continue;     // also background (NaN)
    switch (range) {
      case CrytekSsaoRangeCheck::Smooth:
        occluded += std::clamp(2.0f - delta / radius, 0.0f, 1.0f);
        break;
      case CrytekSsaoRangeCheck::Hard:
        occluded += delta < radius ? 1.0f : 0.0f;
        break;
      case CrytekSsaoRangeCheck::Off:
        occluded += 1.0f;
        break;
    }
  }
  const float a = 1.0f - occluded / float(kernel.size());
  const float out = CrytekSsaoOutput(s.output) == CrytekSsaoOutput::Rescaled ? 2.0f * a : a;
  return std::clamp(out, 0.0f, 1.0f);
}

}  // namespace

std::vector<glm::vec3> crytek_ssao_kernel(int samples, CrytekSsaoDistribution distribution,
                                          int seed) {
  std::vector<glm::vec3> kernel;
  kernel.reserve(std::size_t(std::max(samples, 0)));
  const int pairs = (samples + 1) / 2;
  const auto u = std::uint32_t(seed);
  for (int k = 0; k < pairs; ++k) {
    const glm::vec3 dir = random_unit(u, k, 0, kKernelStream);
    float length = 0.0f;
    if (distribution == CrytekSsaoDistribution::Centre) {
      const float t = float(k) / float(pairs);
      length = kCrytekSsaoInnerScale + (1.0f - kCrytekSsaoInnerScale) * t * t;
    } else {
      length = std::cbrt(pixel_random(u, k, 0, kKernelStream + 2));
    }
    kernel.push_back(length * dir);
    if (int(kernel.size()) < samples) kernel.push_back(-length * dir);
  }
  return kernel;
}

Image crytek_ssao(const GBuffer& g, const CrytekSsaoSettings& s, const RunOptions& options) {
  g.validate();
  validate_settings(s, kCrytekSsaoFields);
  const int w = g.width(), h = g.height();
  const int threads = resolve_threads(options.threads);

  const std::vector<glm::vec3> kernel =
      crytek_ssao_kernel(s.samples, CrytekSsaoDistribution(s.distribution), s.seed);
  glm::vec3 tile[16];
  for (int i = 0; i < 16; ++i) tile[i] = random_unit(std::uint32_t(s.seed), i, 0, kTileStream);
  Image normals;
  if (s.hemisphere) normals = prepared_normals(g, threads);
  // The SIMD kernel's gathers take 32-bit indices.
  if (options.kernel == Kernel::Simd && g.depth.row_stride > 0 &&
      double(g.depth.row_stride) * double(h) < double(std::numeric_limits<std::int32_t>::max()))
    return crytek_ssao_simd(g, s.hemisphere ? normals.data() : nullptr, s, kernel, tile, threads,
                            options.progress);

  const Buffer<float> depth = depth_with_background_as_nan(g, threads);
  const Frame frame{depth.data(), s.hemisphere ? normals.data() : nullptr, w, h, g.camera};

  return image_from_pixels(
      w, h, threads, options.progress, [] { return 0; },
      [&](int, int x, int y) { return crytek_pixel(frame, s, kernel, tile, x, y); });
}

Method crytek_ssao_method() {
  Method m = registered_method("crytek_ssao", "Crytek screen-space ambient occlusion",
                               "Mittring 2007, Finding Next Gen: CryEngine 2 (SIGGRAPH course), "
                               "§8.5.4.3",
                               kCrytekSsaoFields, crytek_ssao);
  m.has_simd_kernel = true;
  return m;
}

}  // namespace aolab
