// Known answers for rtao: on the analytic scenes, traced against their own planes as
// triangles, it meets the closed forms of Cycles' AO within its Monte-Carlo error; an open
// plane is exactly 1 at any tilt and R; the bits do not depend on the thread count; bad
// meshes and settings are errors naming the parameter.
#include "core/raytracing/rtao.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "core/scenes/analytic_scenes.h"
#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::HostileDepths;
using testing::invalid_argument_message;
using testing::min_valid;
using testing::SceneFixture;

/// Half-side of the square each analytic plane becomes: far beyond every scored pixel's R.
constexpr double kExtent = 1000.0;
/// Pixels deeper than this are not scored: their R-ball could reach the planes' edges.
constexpr float kScoredDepth = 400.0f;

// An analytic scene as a G-buffer and as triangles in an Embree scene.
struct TracedScene : SceneFixture {
  RayScene scene;
  TracedScene(const std::string& name, int w, int h, const SettingValues& params = {})
      : SceneFixture(name, w, h, params),
        scene(analytic_scene_mesh(analytic_scene_geometry(name, without_radius(params)), kExtent),
              row_major(SceneFixture::scene.camera_to_world)) {}

  static SettingValues without_radius(SettingValues p) {
    p.erase("radius");
    return p;
  }
};

RtaoSettings settings(float radius, int rays = 64, int seed = 0) {
  RtaoSettings s;
  s.radius = radius;
  s.rays = rays;
  s.seed = seed;
  return s;
}

struct Agreement {
  double mean_ao = 0, mean_reference = 0, sigma = 0;  // sigma: binomial std of mean_ao
  double worst_sigmas = 0;  // the largest |ao − ref| in units of its pixel's binomial std
  int pixels = 0;
};

// rtao against the closed form over the scored pixels. Each pixel's estimate has variance at
// most p(1 − p)/N (stratification only lowers it), so the mean of M pixels has standard
// deviation at most √(Σ p(1 − p)/N)/M.
Agreement agreement(const TracedScene& t, const RtaoSettings& s) {
  const Image ao = rtao(t.g, t.scene, s);
  Agreement a;
  double variance = 0;
  for (int y = 0; y < ao.height(); ++y)
    for (int x = 0; x < ao.width(); ++x) {
      const double ref = t.SceneFixture::scene.reference(x, y);
      if (!t.g.valid(x, y) || std::isnan(ref) || t.g.depth(x, y) > kScoredDepth) continue;
      const double v = ref * (1.0 - ref) / s.rays;
      a.mean_ao += ao(x, y), a.mean_reference += ref, variance += v;
      // A pixel whose answer is 0 or 1 has no noise: allow one ray's weight there.
      const double pixel_sigma = std::max(std::sqrt(v), 1.0 / s.rays);
      a.worst_sigmas = std::max(a.worst_sigmas, std::abs(ao(x, y) - ref) / pixel_sigma);
      ++a.pixels;
    }
  a.mean_ao /= a.pixels, a.mean_reference /= a.pixels;
  a.sigma = std::sqrt(variance) / a.pixels;
  return a;
}

// Tolerances: the mean within 4 binomial standard deviations plus 1e-4 (the analytic
// G-buffer's pixel-centre points are exact, so only float rounding and the offset ε remain);
// every pixel within 5.5 of its own (false failures are far rarer than the binomial bound
// says, the estimates being stratified, and the seeds are fixed).
constexpr double kSigmas = 4.0, kRounding = 1e-4, kPixelSigmas = 5.5;

TEST(Rtao, CeilingMatchesClosedForm) {
  const TracedScene t("ceiling", 96, 64, {{"radius", 2.0}});
  const Agreement a = agreement(t, settings(2.0f, 256));
  ASSERT_GT(a.pixels, 2000);
  EXPECT_NEAR(a.mean_reference, cycles_ao_under_ceiling(1.0, 2.0), 1e-6);
  EXPECT_NEAR(a.mean_ao, a.mean_reference, kSigmas * a.sigma + kRounding);
  EXPECT_LT(a.worst_sigmas, kPixelSigmas);
}

TEST(Rtao, WallAndCreaseMatchClosedForm) {
  for (const char* scene : {"wall", "crease"})
    for (float radius : {0.5f, 2.0f}) {
      const TracedScene t(scene, 96, 54, {{"radius", double(radius)}});
      const Agreement a = agreement(t, settings(radius, 256));
      ASSERT_GT(a.pixels, 2000) << scene;
      EXPECT_LT(a.mean_reference, 0.97) << scene;  // the test sees occlusion
      EXPECT_NEAR(a.mean_ao, a.mean_reference, kSigmas * a.sigma + kRounding)
          << scene << " R " << radius << " over " << a.pixels << " pixels";
      EXPECT_LT(a.worst_sigmas, kPixelSigmas) << scene << " R " << radius;
    }
}

// On the crease line the second plane hides half of the hemisphere: with N = 1024 a pixel's
// standard error is at most √(0.25/1024) = 0.016.
TEST(Rtao, CreaseLineIsOneHalfPerPixel) {
  const TracedScene t("crease", 96, 54, {{"radius", 1.0}});
  const Image ao = rtao(t.g, t.scene, settings(1.0f, 1024));
  for (int x = 30; x < 66; ++x)
    EXPECT_NEAR(ao(x, 26), t.SceneFixture::scene.reference(x, 26), 4 * 0.016) << x;
}

// The offset ε keeps a surface from occluding itself at any grazing angle and any R: an open
// plane is exactly 1. Pixels so far that 0.01 px exceeds R/2 are made background: there ε
// would reach R, and rtao refuses to trace (docs/conventions.md, "Ranges").
TEST(Rtao, OpenPlaneIsExactlyOne) {
  for (double tilt : {0.0, 60.0, 89.0}) {
    const TracedScene t("plane", 64, 36, {{"tilt", tilt}, {"azimuth", 30}});
    for (float radius : {0.01f, 1.0f, 1e30f}) {
      GBuffer near = t.g;
      near.background_depth = std::min(
          t.g.background_depth,
          float(0.5 * radius * std::min(t.g.camera.fx, t.g.camera.fy) / kRtaoOffsetPixels));
      EXPECT_EQ(min_valid(rtao(near, t.scene, settings(radius, 64)), near), 1.0f)
          << tilt << " " << radius;
    }
  }
}

// The wall's planes as 50 m squares, the world moved by `shift` along x (the camera with it).
struct ShiftedWall {
  SceneFixture f{"wall", 48, 27};
  TriangleMesh mesh = analytic_scene_mesh(analytic_scene_geometry("wall", {}), 50.0);
  Matrix4 c2w = row_major(f.scene.camera_to_world);
  explicit ShiftedWall(float shift) {
    for (std::size_t k = 0; k < mesh.vertices.size(); k += 3) mesh.vertices[k] += shift;
    c2w[3] += shift;
  }
};

// The offset's rounding term scales with the triangles a ray can reach: a small triangle far
// away changes no bit (it used to lift every ray by 5 m, and R = 0.5 then found nothing).
TEST(Rtao, ASmallTriangleFarAwayChangesNothing) {
  ShiftedWall w(0.0f);
  const Image near = rtao(w.f.g, RayScene(w.mesh, w.c2w), settings(0.5f, 16));
  const auto n = std::uint32_t(w.mesh.vertex_count());
  w.mesh.vertices.insert(w.mesh.vertices.end(),
                         {1e7f, 1e7f, 0, 1e7f + 1, 1e7f, 0, 1e7f, 1e7f + 1, 0});
  w.mesh.triangles.insert(w.mesh.triangles.end(), {n, n + 1, n + 2});
  const Image far = rtao(w.f.g, RayScene(w.mesh, w.c2w), settings(0.5f, 16));
  EXPECT_EQ(far.pixels(), near.pixels());
  EXPECT_LT(*std::min_element(near.pixels().begin(), near.pixels().end()), 0.9f);
}

// Where the scene's coordinates are so large that ε reaches R, rtao refuses, and its message
// is rtao_range's, with the numbers; at home the same scene is neither refused nor warned.
TEST(Rtao, AnOffsetReachingRIsRefusedWithItsNumbers) {
  const ShiftedWall far(1e7f), home(0.0f);
  const RayScene far_scene(far.mesh, far.c2w);
  const RtaoRange range = rtao_range(far.f.g, far_scene, 0.5f);
  EXPECT_GT(range.pixels, 1000u);
  EXPECT_EQ(range.refused, range.pixels);
  EXPECT_EQ(range.warned, range.pixels);
  EXPECT_EQ(invalid_argument_message([&] { rtao(far.f.g, far_scene, settings(0.5f, 4)); }),
            range.refusal());
  EXPECT_NE(range.refusal().find("camera from the world origin |c| = 1e+07"), std::string::npos)
      << range.refusal();
  EXPECT_TRUE(range.warning().empty());
  const RtaoRange ok = rtao_range(home.f.g, RayScene(home.mesh, home.c2w), 0.5f);
  EXPECT_EQ(ok.pixels, range.pixels);
  EXPECT_EQ(ok.warned, 0u);
  EXPECT_TRUE(ok.refusal().empty() && ok.warning().empty());
  EXPECT_LT(ok.largest.scale, 200.0);  // the 50 m squares, not the world 1e7 away
}

TEST(Rtao, EmptyMeshGivesOne) {
  const SceneFixture f("blocks", 32, 18);
  const RayScene empty(TriangleMesh{}, row_major(f.scene.camera_to_world));
  EXPECT_EQ(empty.triangle_count(), 0u);
  EXPECT_EQ(min_valid(rtao(f.g, empty, settings(1.0f, 16)), f.g), 1.0f);
}

TEST(Rtao, SameBitsForAnyThreadCount) {
  const TracedScene t("blocks", 64, 36);
  testing::expect_same_bits_for_thread_counts(
      [&](int threads) { return rtao(t.g, t.scene, settings(1.0f, 16), {threads}); }, "rtao");
}

// One ray per pixel answers 0 or 1; the seed moves the noise, not the mean.
TEST(Rtao, OneRayIsBinaryAndSeedMovesNoiseNotMean) {
  const TracedScene t("crease", 96, 54);
  const Image a = rtao(t.g, t.scene, settings(1.0f, 1, 0));
  const Image b = rtao(t.g, t.scene, settings(1.0f, 1, 7));
  double mean_a = 0, mean_b = 0;
  int differ = 0;
  for (std::size_t i = 0; i < a.pixels().size(); ++i) {
    EXPECT_TRUE(a.pixels()[i] == 0.0f || a.pixels()[i] == 1.0f) << i;
    mean_a += a.pixels()[i], mean_b += b.pixels()[i];
    differ += a.pixels()[i] != b.pixels()[i];
  }
  EXPECT_GT(differ, 100);
  // 5184 pixels at N = 1: the mean's standard deviation is at most √(0.25/5184) ≈ 6.9e-3.
  const double n = double(a.pixels().size());
  EXPECT_NEAR(mean_a / n, mean_b / n, 4 * 6.9e-3 * std::sqrt(2.0));
}

TEST(Rtao, BackgroundHostileDepthsAndTinyImagesGiveOneOrFiniteValues) {
  const TracedScene t("blocks", 41, 23);
  HostileDepths hostile(t.g);
  hostile.every_third_pixel_of_rows();
  const Image ao = rtao(hostile.g, t.scene, settings(1.0f, 8));
  hostile.expect_ao_one(ao, "rtao");
  testing::expect_in_unit_interval(ao, "rtao hostile");
  for (const auto& [w, h] : testing::tiny_image_sizes()) {
    const TracedScene tiny("blocks", w, h);
    testing::expect_in_unit_interval(rtao(tiny.g, tiny.scene, settings(1.0f, 8)),
                                     std::to_string(w) + "x" + std::to_string(h));
  }
}

TEST(Rtao, SettingsAndGBufferAreChecked) {
  const TracedScene t("blocks", 16, 9);
  EXPECT_NE(invalid_argument_message([&] { rtao(t.g, t.scene, settings(1.0f, 0)); }).find("rays"),
            std::string::npos);
  EXPECT_NE(invalid_argument_message([&] { rtao(t.g, t.scene, settings(0.0f)); }).find("radius"),
            std::string::npos);
  EXPECT_NE(invalid_argument_message([&] {
              rtao(t.g, t.scene, settings(std::numeric_limits<float>::quiet_NaN()));
            }).find("radius"),
            std::string::npos);
  GBuffer no_normal = t.g;
  no_normal.normal = {};
  EXPECT_NE(
      invalid_argument_message([&] { rtao(no_normal, t.scene, settings(1.0f)); }).find("normal"),
      std::string::npos);
}

TEST(RayScene, MalformedMeshesAndCamerasAreNamed) {
  const Matrix4 identity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  TriangleMesh m;
  m.vertices = {0, 0, -1, 1, 0, -1, 0, 1, -1};
  m.triangles = {0, 1, 3};
  EXPECT_NE(invalid_argument_message([&] { RayScene(m, identity); }).find("triangles"),
            std::string::npos);
  m.triangles = {0, 1};
  EXPECT_NE(invalid_argument_message([&] { RayScene(m, identity); }).find("triangles"),
            std::string::npos);
  m.triangles = {0, 1, 2};
  m.vertices[4] = std::numeric_limits<float>::infinity();
  EXPECT_NE(invalid_argument_message([&] { RayScene(m, identity); }).find("vertices"),
            std::string::npos);
  // Beyond Embree's range (its FLT_LARGE), where it would drop the triangle without a word.
  m.vertices[4] = 1e25f;
  const std::string far = invalid_argument_message([&] { RayScene(m, identity); });
  EXPECT_NE(far.find("vertices must have view-space coordinates below 1.844e+18"),
            std::string::npos)
      << far;
  EXPECT_NE(far.find("the first vertex 1 at world (1, 1e+25, -1)"), std::string::npos) << far;
  m.vertices[4] = 0;
  Matrix4 scaled = identity;
  scaled[0] = 2;
  EXPECT_NE(invalid_argument_message([&] { RayScene(m, scaled); }).find("camera_to_world"),
            std::string::npos);
  Matrix4 projective = identity;
  projective[12] = 0.5;
  EXPECT_NE(invalid_argument_message([&] { RayScene(m, projective); }).find("camera_to_world"),
            std::string::npos);
  EXPECT_NE(invalid_argument_message([&] { RayScene(m, identity, -1); }).find("threads"),
            std::string::npos);
  const RayScene ok(m, identity);
  EXPECT_EQ(ok.triangle_count(), 1u);
  EXPECT_GE(ok.build_seconds(), 0.0);
}

// The view-space move: a triangle in front of a camera translated and turned in the world is
// hit where the camera sees it, and missed beside it.
TEST(RayScene, WorldTrianglesAreMovedIntoViewSpace) {
  // A camera at world (10, 0, 0) looking down world −x: its view axes are the matrix's
  // columns, x_view = world y, y_view = world z, z_view = world x (x × y = z).
  const Matrix4 c2w = {0, 0, 1, 10, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1};
  TriangleMesh m;  // a big triangle in the world plane x = 5, i.e. 5 in front of the camera
  m.vertices = {5, -100, -100, 5, 100, -100, 5, 0, 100};
  m.triangles = {0, 1, 2};
  const RayScene s(m, c2w);
  const float origin[3] = {0, 0, 0};
  const float ahead[3] = {0, 0, -1}, behind[3] = {0, 0, 1};
  EXPECT_TRUE(s.occluded(origin, ahead, 5.5f));
  EXPECT_FALSE(s.occluded(origin, ahead, 4.5f));
  EXPECT_FALSE(s.occluded(origin, behind, 100.0f));
}

}  // namespace
}  // namespace aolab

namespace aolab {
namespace {

// Packets (16- and 8-wide) and single rays answer alike, whatever the count of rays: the
// packet path is a speed-up, never a different answer.
TEST(RayScene, PacketsAgreeWithSingleRays) {
  const TracedScene t("blocks", 8, 8);
  const glm::vec3 p = t.g.camera.view_position(4.5f, 5.5f, t.g.depth(4, 5));
  const float origin[3] = {p.x, p.y, p.z + 1e-3f};
  std::vector<float> dirs, dx, dy, dz;
  for (int k = 0; k < 41; ++k) {  // directions over the sphere, many blocked, many free
    const double z = 1.0 - 2.0 * (k + 0.5) / 41, r = std::sqrt(1.0 - z * z), phi = 2.4 * k;
    dirs.insert(dirs.end(), {float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)});
    dx.push_back(dirs[dirs.size() - 3]), dy.push_back(dirs[dirs.size() - 2]);
    dz.push_back(dirs.back());
  }
  int hits = 0;
  for (int count : {1, 3, 4, 7, 8, 15, 16, 17, 24, 31, 41}) {
    std::unique_ptr<bool[]> blocked(new bool[std::size_t(count)]);
    t.scene.occluded_from(origin, dx.data(), dy.data(), dz.data(), count, 2.0f, blocked.get());
    for (int k = 0; k < count; ++k) {
      EXPECT_EQ(blocked[std::size_t(k)], t.scene.occluded(origin, &dirs[3 * std::size_t(k)], 2.0f))
          << count << " rays, ray " << k;
      hits += blocked[std::size_t(k)];
    }
  }
  EXPECT_GT(hits, 10);
}

}  // namespace
}  // namespace aolab
