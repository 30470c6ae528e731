// What every registered method promises, checked once for all of them through the registry:
// exactly 1 on open planes and on background or invalid depth, finite results in [0, 1],
// the same bits for any thread count, settings errors that name the setting, the normals a
// method needs, progress and cancelling. Each runs at the method's defaults, with each
// boolean setting flipped, at each value of each choice setting and in the layouts listed
// in extra_configurations (one change at a time). Method-specific known answers live beside
// each method.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/methods/registry.h"
#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::invalid_argument_message;

std::vector<std::string> method_names() {
  std::vector<std::string> names;
  for (const Method& m : methods()) names.push_back(m.name);
  return names;
}

// Settings of a numeric kind that change a method's sampling layout, so that the checks also
// cover layouts no boolean or choice reaches.
const std::vector<SettingValues>& extra_configurations(const std::string& method) {
  static const std::map<std::string, std::vector<SettingValues>> table = {
      {"hbao", {{{"steps", 4}}, {{"steps", 16}, {"directions", 3}}}},
      {"pyramid_hbao",
       {{{"reduction", 3}, {"samples", 16}, {"gaussian_filter", 0}},
        {{"reduction", 2}, {"samples", 4}, {"gaussian_filter", 0}},
        {{"levels", 2}, {"directions", 5}}}},
      // §5.1/§5.2 layouts: aligned sets of other sizes and strides, uniform directions with
      // dense and sparse steps, a seeded lattice, the strictest gather, the hull search.
      {"lsao",
       {{{"template_size", 1}, {"directions", 8}},
        {{"template_size", 3}, {"directions", 24}, {"line_spacing", 2.5}},
        {{"template_stride", 2}},
        {{"template_size", 0}, {"directions", 12}, {"step", 1}, {"line_spacing", 1}},
        {{"template_size", 0}, {"directions", 8}, {"step", 2.7}, {"sampling", 1}},
        {{"seed", 12345}, {"falloff", 3}},
        {{"gather_depth_tolerance", 0}, {"normal_aware_gather", 1}},
        {{"hull_search", 16}}}},
      {"chebyshev", {{{"kernel_mode", 0}, {"kernel_radius", 3}}, {{"max_kernel_radius", 8}}}},
      // One slice, dense steps with the thickness heuristic and falloff; many slices, one step.
      {"gtao",
       {{{"slices", 1}, {"steps", 16}, {"thickness", 0.5}, {"falloff", 0.615}},
        {{"slices", 9}, {"steps", 1}, {"multi_bounce", 1}, {"albedo", 1}}}},
      // 64 sectors with dense steps, a height field and the exact cosine weights; one sector,
      // many slices, one step, thickness 0, the sphere clip; an odd sector count with the
      // memo's mean of cosine-weighted slices.
      {"bitmask",
       {{{"sectors", 64}, {"steps", 16}, {"thickness", 1e30}, {"weighting", 1}},
        {{"sectors", 1}, {"slices", 9}, {"steps", 1}, {"thickness", 0}, {"radius_clip", 2}},
        {{"sectors", 7}, {"rounding", 2}, {"weighting", 1}, {"normalization", 1}}}},
      // Alchemy: one tap, many taps on a fixed spiral with the contrast exponent.
      {"alchemy", {{{"samples", 1}}, {{"samples", 40}, {"turns", 7}, {"contrast", 2}}}},
      // SAO: full resolution only, every tap on a coarse level, a wide sparse filter.
      {"sao",
       {{{"max_mip_level", 0}, {"samples", 3}},
        {{"log_max_offset", 0}, {"samples", 30}, {"contrast", 3}},
        {{"filter_radius", 12}, {"filter_stride", 5}, {"edge_sharpness", 0}}}},
      // Crytek SSAO: one point (an unpaired kernel), an odd count, many points in the ball.
      {"crytek_ssao", {{{"samples", 1}}, {{"samples", 7}}, {{"samples", 64}, {"distribution", 1}}}},
      {"vao", {{{"samples", 1}}, {{"samples", 64}}}},
      {"vao_pp",
       {{{"culling", 0}, {"poisson_samples", 0}, {"samples", 32}},
        {{"adaptive_sampling", 0}, {"filter_taps", 9}},
        {{"samples", 2}, {"bleeding_sample_step", 4}, {"color_bleeding", 1}}}},
      // One unstratified ray, a stratification with unequal columns, finite thicknesses.
      {"screen_space_limit",
       {{{"rays", 1}}, {{"rays", 5}, {"thickness", 0.05}, {"seed", 3}}, {{"thickness", 0}}}},
  };
  static const std::vector<SettingValues> none;
  const auto it = table.find(method);
  return it == table.end() ? none : it->second;
}

// What the suite runs a method with instead of its defaults, for bounds too slow at their
// defaults for a suite of many runs: the screen-space limit's 256 rays per pixel march
// every pixel a ray crosses, up to the image border at the huge radii, and the contract
// does not depend on the number of rays.
SettingValues suite_base(const std::string& method) {
  if (method == "screen_space_limit") return {{"rays", 4}};
  return {};
}

// The configurations every check runs (without radius): the defaults, each boolean setting
// flipped, each other value of each choice setting, and the extra layouts, each on top of
// suite_base.
std::vector<SettingValues> configurations(const Method& m) {
  std::vector<SettingValues> out{{}};
  for (const SettingDescription& d : m.settings) {
    if (d.type == SettingType::Bool) out.push_back({{d.name, d.default_value != 0.0 ? 0.0 : 1.0}});
    if (d.type == SettingType::Choice)
      for (double v = d.min; v <= d.max; ++v)
        if (v != d.default_value) out.push_back({{d.name, v}});
  }
  for (const SettingValues& v : extra_configurations(m.name)) out.push_back(v);
  const SettingValues base = suite_base(m.name);
  for (SettingValues& v : out) v.insert(base.begin(), base.end());  // keeps v's own values
  return out;
}

std::string describe(const SettingValues& values) {
  std::ostringstream s;
  for (const auto& [name, value] : values) s << name << '=' << value << ' ';
  return values.empty() ? "defaults" : s.str();
}

bool is(const SettingValues& values, const std::string& name, double value) {
  const auto it = values.find(name);
  return it != values.end() && it->second == value;
}

// The steepest plane tilt (degrees) at which a configuration is exactly 1 on an open plane:
// any tilt, except where the method's documentation says otherwise.
double exact_plane_tilt(const std::string& method, const SettingValues& v) {
  // hbao.h, per_sample_tangent: with one tangent per direction snapping makes a tilted plane
  // occlude itself slightly.
  if (method == "hbao" && is(v, "per_sample_tangent", 0)) return 0;
  // vao.h, view_ray_pipes: pipes parallel to the view axis make tilted planes occlude
  // themselves slightly off-axis.
  if ((method == "vao" || method == "vao_pp") && is(v, "view_ray_pipes", 0)) return 0;
  // chebyshev.h: eq. 2 counts a tilted plane's convexity in the image on both sides of the
  // mean; without shrinking, a window at a plane's far edge against background darkens.
  if (method == "chebyshev" && (is(v, "ignore_unoccluded", 0) || is(v, "shrink_at_background", 0)))
    return 0;
  // gtao.h, GtaoNormalization::Slices: the memo's 1/N is not 1 where n ≠ v, even on a plane
  // facing the camera off-axis (the unoccluded integrand varies with the slice).
  if (method == "gtao" && is(v, "normalization", 1)) return -1;
  // bitmask.h, BitmaskNormalization::Slices with cosine weighting: the same 1/N of the memo.
  if (method == "bitmask" && is(v, "normalization", 1) && is(v, "weighting", 1)) return -1;
  // sao.h, SaoTapPosition::Tap: a coarse depth placed at the tap's own pixel moves it off a
  // tilted plane (exact on a plane facing the camera, whose depth is constant).
  if (method == "sao" && is(v, "tap_position", 1)) return 0;
  // crytek_ssao.h: normal-free, as published, an open plane gives 1/2; rescaled (or with the
  // hemisphere) it is exactly 1 where the depth buffer is the plane at every point's
  // projection, on a plane facing the camera (a tilted plane's depth changes within a pixel,
  // so points just above it can read a nearer depth). One unpaired point breaks the half.
  if (method == "crytek_ssao") {
    const bool hemisphere = is(v, "hemisphere", 1);
    if (is(v, "output", 1) && !hemisphere) return -1;
    if (is(v, "samples", 1) || is(v, "samples", 7)) return hemisphere ? 0 : -1;
    return 0;
  }
  if (method == "lsao") {
    // lsao.h, tangent_strategy: the real tangent is exact only up to the rounding of the
    // normal (lsao_test checks > 0.999 on tilted planes).
    if (is(v, "tangent_strategy", 1) || is(v, "tangent_strategy", 2)) return -1;
    // Opposite sweeps cancel to the bit only where they see the plane at mirrored
    // elevations, on a plane facing the camera (lsao_test checks tilted planes against
    // eq. 1, and gentle ones at R = 1 for exactly 1).
    return 0;
  }
  return 90;
}

// A G-buffer with every pass: depth, normals, colour (white unless given) and emission, so
// that every setting can run; white colour leaves colour bleeding's A·B equal to A.
struct FullGBuffer {
  Image depth, normal, color, emission;
  GBuffer g;
  FullGBuffer(Image depth_, Image normal_, const CameraIntrinsics& camera, float r = 1.0f,
              float green = 1.0f, float b = 1.0f, float emit = 0.0f)
      : depth(std::move(depth_)),
        normal(std::move(normal_)),
        color(depth.width(), depth.height(), 3),
        emission(depth.width(), depth.height(), 3, emit) {
    for (int y = 0; y < depth.height(); ++y)
      for (int x = 0; x < depth.width(); ++x)
        color(x, y, 0) = r, color(x, y, 1) = green, color(x, y, 2) = b;
    g.depth = depth.view();
    g.normal = normal.view();
    g.color = color.view();
    g.emission = emission.view();
    g.camera = camera;
  }
  explicit FullGBuffer(AnalyticGBuffer s, float r = 1.0f, float green = 1.0f, float b = 1.0f,
                       float emit = 0.0f)
      : FullGBuffer(std::move(s.depth), std::move(s.normal), s.camera, r, green, b, emit) {}
  FullGBuffer(const FullGBuffer&) = delete;
  FullGBuffer& operator=(const FullGBuffer&) = delete;
};

// Depths that are all background by the rule of gbuffer.h.
const float kInvalidDepths[] = {1e10f, INFINITY,  NAN, 0.0f,
                                -1.0f, -INFINITY, 1e9f /* = kDefaultBackgroundDepth */};

// A random G-buffer: depths in [1, 3] with every tenth pixel or so invalid (each kind of
// invalid depth), random normals (some zero, NaN or facing away, which prepared_normals
// repairs), random colour in [0, 1] and emission in [0, 2].
std::unique_ptr<FullGBuffer> random_gbuffer(int w, int h, std::uint64_t seed) {
  Image depth = testing::random_image(w, h, seed, 1.0f, 3.0f);
  const Image pick = testing::random_image(w, h, seed + 1);
  for (std::size_t i = 0; i < depth.pixels().size(); ++i)
    if (pick.pixels()[i] < 0.1f)
      depth.pixels()[i] = kInvalidDepths[i % (sizeof(kInvalidDepths) / sizeof(float))];
  Image normal(w, h, 3);
  const Image nx = testing::random_image(w, h, seed + 2, -1, 1),
              ny = testing::random_image(w, h, seed + 3, -1, 1),
              nz = testing::random_image(w, h, seed + 4, -1, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      normal(x, y, 0) = nx(x, y), normal(x, y, 1) = ny(x, y), normal(x, y, 2) = nz(x, y);
      if ((x + 7 * y) % 53 == 0) normal(x, y, 0) = normal(x, y, 1) = normal(x, y, 2) = 0.0f;
      if ((x + 11 * y) % 61 == 0) normal(x, y, 1) = NAN;
    }
  auto out = std::make_unique<FullGBuffer>(
      std::move(depth), std::move(normal),
      CameraIntrinsics{float(w), float(w), float(w) / 2, float(h) / 2});
  const Image r = testing::random_image(w, h, seed + 5),
              e = testing::random_image(w, h, seed + 6, 0, 2);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        out->color(x, y, c) = r(x, y) * float(c + 1) / 3.0f;
        out->emission(x, y, c) = e(x, y);
      }
  return out;
}

// The `step` scene with its raised half replaced by invalid depths of every kind: a floor
// facing the camera beside nothing, which must be exactly 1 everywhere.
std::unique_ptr<FullGBuffer> floor_beside_background() {
  AnalyticGBuffer s = analytic_scene("step", 120, 80);
  for (int y = 0; y < s.depth.height(); ++y)
    for (int x = s.depth.width() / 2; x < s.depth.width(); ++x)
      s.depth(x, y) = kInvalidDepths[std::size_t(x + y) % (sizeof(kInvalidDepths) / sizeof(float))];
  return std::make_unique<FullGBuffer>(std::move(s));
}

class MethodConformance : public ::testing::TestWithParam<std::string> {
 protected:
  const Method& method() const { return find_method(GetParam()); }

  // compute() at radius R with `values`, on `threads` threads.
  Image run(const GBuffer& g, SettingValues values, double radius, int threads = 2) const {
    values["radius"] = radius;
    RunOptions options;
    options.threads = threads;
    return compute(GetParam(), g, values, options);
  }
};

// Open planes seen at a tilt (degrees) towards an azimuth, with a horizontal field of view.
struct PlaneCase {
  double tilt, azimuth, fov;
};
const PlaneCase kPlanes[] = {{0, 0, 60},   {0, 0, 90},      {30, 45, 60}, {60, 0, 90},
                             {85, 30, 60}, {-85, 200, 120}, {89, 90, 30}};

// An open (unoccluded) plane: nothing lies above the tangent plane of any
// pixel, so every method gives exactly 1 at every geometry pixel, tilt, field of view and
// radius (background pixels are 1 anyway).
TEST_P(MethodConformance, OpenPlaneIsExactlyOne) {
  for (const SettingValues& config : configurations(method())) {
    const double max_tilt = exact_plane_tilt(GetParam(), config);
    for (const PlaneCase& c : kPlanes) {
      if (std::abs(c.tilt) > max_tilt) continue;
      const FullGBuffer f(analytic_scene(
          "plane", 160, 90, {{"tilt", c.tilt}, {"azimuth", c.azimuth}, {"fov", c.fov}}));
      for (double radius : {1e-4, 0.05, 0.3, 1.0, 5.0, 1e3, 1e30}) {
        const Image ao = run(f.g, config, radius);
        float lowest = 1.0f;
        for (float v : ao.pixels()) lowest = std::min(lowest, v);
        EXPECT_EQ(lowest, 1.0f) << describe(config) << "tilt " << c.tilt << " azimuth " << c.azimuth
                                << " fov " << c.fov << " R " << radius;
      }
    }
  }
}

// Background (every kind of invalid depth) is 1 and never occludes: a floor facing the camera
// beside it stays exactly 1, at radii that reach far into the background.
TEST_P(MethodConformance, BackgroundIsOneAndNeverOccludes) {
  const auto f = floor_beside_background();
  for (const SettingValues& config : configurations(method())) {
    if (exact_plane_tilt(GetParam(), config) < 0) continue;  // not exact on any plane
    for (double radius : {0.5, 5.0, 1e3}) {
      const Image ao = run(f->g, config, radius);
      for (int y = 0; y < ao.height(); ++y)
        for (int x = 0; x < ao.width(); ++x)
          for (int c = 0; c < ao.channels(); ++c)
            ASSERT_EQ(ao(x, y, c), 1.0f) << describe(config) << "R " << radius << " at " << x << ","
                                         << y << " depth " << f->depth(x, y);
    }
  }
}

// On a random G-buffer with invalid depths, broken normals and any colour, every result is
// finite and in [0, 1], the size of the input, 1 channel or RGB, and exactly 1 wherever the
// depth is invalid.
TEST_P(MethodConformance, ResultIsFiniteInUnitRangeAndOneOnInvalidDepth) {
  const auto f = random_gbuffer(64, 48, 11);
  for (const SettingValues& config : configurations(method()))
    for (double radius : {0.05, 0.5, 5.0}) {
      const Image ao = run(f->g, config, radius);
      ASSERT_EQ(ao.width(), 64);
      ASSERT_EQ(ao.height(), 48);
      ASSERT_TRUE(ao.channels() == 1 || ao.channels() == 3) << ao.channels();
      for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 64; ++x)
          for (int c = 0; c < ao.channels(); ++c) {
            const float v = ao(x, y, c);
            ASSERT_TRUE(v >= 0.0f && v <= 1.0f)
                << describe(config) << "R " << radius << " at " << x << "," << y << ": " << v;
            if (!f->g.valid(x, y)) {
              ASSERT_EQ(v, 1.0f) << describe(config) << x << "," << y;
            }
          }
    }
}

// Work is split into row bands handed to threads in any order: 1, 2 and 7 threads give the
// same bits.
TEST_P(MethodConformance, BitIdenticalForAnyThreadCount) {
  const FullGBuffer f(analytic_scene("blocks", 200, 120), 0.8f, 0.3f, 0.2f, 0.5f);
  for (const SettingValues& config : configurations(method())) {
    const Image one = run(f.g, config, 0.5, 1);
    EXPECT_EQ(one.pixels(), run(f.g, config, 0.5, 2).pixels()) << describe(config);
    EXPECT_EQ(one.pixels(), run(f.g, config, 0.5, 7).pixels()) << describe(config);
  }
}

TEST_P(MethodConformance, UnknownSettingIsRejectedListingTheValidNames) {
  const FullGBuffer f(analytic_scene("plane", 16, 9));
  const std::string message = invalid_argument_message([&] {
    run(f.g, {{"no_such_setting", 1}}, 1.0);
  });
  EXPECT_NE(message.find("unknown setting 'no_such_setting' for " + GetParam()), std::string::npos)
      << message;
  for (const SettingDescription& d : method().settings)
    EXPECT_NE(message.find(d.name), std::string::npos) << d.name << " missing from: " << message;
}

// Every setting outside its range (below, above, NaN, infinite, a fraction for an integer, a
// boolean other than 0 or 1) is rejected with a message that starts with the setting's name.
TEST_P(MethodConformance, OutOfRangeSettingIsRejectedNamingIt) {
  const FullGBuffer f(analytic_scene("plane", 16, 9));
  for (const SettingDescription& d : method().settings) {
    std::vector<double> bad = {NAN, INFINITY, -INFINITY};
    if (d.type == SettingType::Bool) {
      bad.insert(bad.end(), {2.0, 0.5, -1.0});
    } else {
      bad.push_back(d.min - std::max(1.0, std::abs(d.min)));
      bad.push_back(d.max + std::max(1.0, std::abs(d.max)));
      if (d.type != SettingType::Float && d.max > d.min) bad.push_back(d.min + 0.5);
    }
    for (double value : bad) {
      SettingValues values{{"radius", 1.0}};
      values[d.name] = value;
      const std::string message =
          invalid_argument_message([&] { compute(GetParam(), f.g, values); });
      EXPECT_EQ(message.rfind(d.name + " ", 0), 0u)
          << d.name << " = " << value << " gave: '" << message << "'";
    }
  }
  EXPECT_EQ(invalid_argument_message([&] { compute(GetParam(), f.g, {}); }).rfind("radius", 0), 0u);
}

// A method that reads normals says so (Method::needs_normal) and rejects a G-buffer without
// them, through compute() and through its own entry point (Method::run); one that does not
// runs on depth alone.
TEST_P(MethodConformance, MissingNormalsAreRejectedIffTheMethodNeedsThem) {
  const FullGBuffer f(analytic_scene("blocks", 48, 27));
  GBuffer g = f.g;
  g.normal = {};
  const SettingValues values{{"radius", 0.5}};
  const std::string via_compute = invalid_argument_message([&] { compute(GetParam(), g, values); });
  const std::string via_run = invalid_argument_message([&] { method().run(g, values, {}); });
  if (method().needs_normal) {
    EXPECT_EQ(via_compute.rfind("normal is required by " + GetParam(), 0), 0u) << via_compute;
    EXPECT_EQ(via_run.rfind("normal is required by " + GetParam(), 0), 0u) << via_run;
  } else {
    EXPECT_EQ(via_compute, "");
    EXPECT_EQ(via_run, "");
  }
}

// Progress: the rows done reach the rows announced; a cancelled computation throws Cancelled.
TEST_P(MethodConformance, ReportsProgressAndCancels) {
  const FullGBuffer f(analytic_scene("blocks", 64, 36));
  for (const SettingValues& config : configurations(method())) {
    SettingValues values = config;
    values["radius"] = 0.5;
    Progress progress;
    RunOptions options;
    options.progress = &progress;
    compute(GetParam(), f.g, values, options);
    EXPECT_GT(progress.total.load(), 0) << describe(config);
    EXPECT_EQ(progress.done.load(), progress.total.load()) << describe(config);
    Progress cancelled;
    cancelled.cancel = true;
    options.progress = &cancelled;
    EXPECT_THROW(compute(GetParam(), f.g, values, options), Cancelled) << describe(config);
  }
}

INSTANTIATE_TEST_SUITE_P(Methods, MethodConformance, ::testing::ValuesIn(method_names()),
                         [](const auto& param_info) { return param_info.param; });

TEST(Registry, UnknownMethodIsRejectedListingTheMethods) {
  const FullGBuffer f(analytic_scene("plane", 16, 9));
  const std::string message = invalid_argument_message([&] {
    compute("nope", f.g, {{"radius", 1}});
  });
  EXPECT_EQ(message.rfind("method must be one of ", 0), 0u) << message;
  for (const std::string& name : method_names())
    EXPECT_NE(message.find(name), std::string::npos) << message;
}

}  // namespace
}  // namespace aolab
