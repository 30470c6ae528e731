// Image files: G-buffer EXR + sidecar round trips in Blender's channel layout, world-to-view
// normals, AO images as EXR/PNG, errors, and atomic writes that leave no temporary files.
#include "core/io/image_io.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

namespace fs = std::filesystem;

constexpr float kCyclesBackground = 1e10f;  // what Cycles writes where no geometry is hit
// Half floats carry 11 significant bits: a relative error of 2^-11 ~ 4.9e-4, so 1e-3
// bounds the error of values in [-1, 1].
constexpr float kHalfTolerance = 1e-3f;

// A small hand-made G-buffer that owns its pixels: a 7x5 tilted plane with a background
// corner, unit normals that vary per pixel, a colour ramp and an AO ramp.
struct TestGBuffer {
  static constexpr int kWidth = 7, kHeight = 5;
  Image depth{kWidth, kHeight, 1}, normal{kWidth, kHeight, 3}, color{kWidth, kHeight, 3},
      ao{kWidth, kHeight, 1};
  GBuffer g;

  TestGBuffer() {
    for (int y = 0; y < kHeight; ++y)
      for (int x = 0; x < kWidth; ++x) {
        // Depths that half could not hold exactly, to show depth stays float32.
        depth(x, y) = 2.0f + 0.123457f * float(x) + 0.0713f * float(y);
        const float nx = 0.1f * float(x - 3), ny = 0.15f * float(y - 2);
        const float len = std::sqrt(nx * nx + ny * ny + 1.0f);
        normal(x, y, 0) = nx / len;
        normal(x, y, 1) = ny / len;
        normal(x, y, 2) = 1.0f / len;
        for (int c = 0; c < 3; ++c) color(x, y, c) = float(x + y + c) / 16.0f;
        ao(x, y) = float(x * kHeight + y) / float(kWidth * kHeight);
      }
    depth(0, 0) = depth(1, 0) = depth(6, 4) = kCyclesBackground;
    g.depth = depth.view();
    g.normal = normal.view();
    g.color = color.view();
    g.camera = CameraIntrinsics{6.5f, 6.25f, 3.5f, 2.5f};
  }
};

class ImageIo : public testing::TempDirTest {
 protected:
  std::set<std::string> files() const {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) names.insert(e.path().filename().string());
    return names;
  }
};

TEST_F(ImageIo, GBufferRoundTripIsExactForDepthAndWithinHalfForTheRest) {
  TestGBuffer t;
  const std::string exr = path("scene.exr");
  save_gbuffer(exr, t.g, t.ao.view(), R"({"ao_distance": 1.25, "samples": 16})");
  EXPECT_EQ(files(), (std::set<std::string>{"scene.exr", "scene.json"}));

  const GBufferData d = load_gbuffer(exr);
  ASSERT_EQ(d.depth.width(), 7);
  ASSERT_EQ(d.depth.height(), 5);
  ASSERT_EQ(d.normal.channels(), 3);
  ASSERT_EQ(d.color.channels(), 3);
  ASSERT_EQ(d.ao.channels(), 1);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x) {
      EXPECT_EQ(d.depth(x, y), t.depth(x, y)) << x << ", " << y;  // float32: bit-exact
      EXPECT_NEAR(d.ao(x, y), t.ao(x, y), kHalfTolerance);
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(d.normal(x, y, c), t.normal(x, y, c), kHalfTolerance);
        EXPECT_NEAR(d.color(x, y, c), t.color(x, y, c), kHalfTolerance);
      }
    }
  EXPECT_EQ(d.sidecar.fx, double(6.5f));
  EXPECT_EQ(d.sidecar.fy, double(6.25f));
  EXPECT_EQ(d.sidecar.normal_space, "view");
  EXPECT_EQ(d.sidecar.ao_distance, 1.25);
  EXPECT_EQ(d.sidecar.samples, 16);

  const GBuffer v = d.view();
  EXPECT_NO_THROW(v.validate());
  EXPECT_EQ(v.camera.fx, 6.5f);
  EXPECT_EQ(v.camera.cy, 2.5f);
  EXPECT_EQ(v.background_depth, kDefaultBackgroundDepth);
  EXPECT_FALSE(v.valid(0, 0));  // the 1e10 background survives the trip
  EXPECT_TRUE(v.valid(2, 0));
}

TEST_F(ImageIo, ChannelsAreNamedLikeBlenderPasses) {
  TestGBuffer t;
  save_gbuffer(path("scene.exr"), t.g, t.ao.view(), "{}");
  const std::vector<std::string> names = exr_channel_names(path("scene.exr"));
  const std::set<std::string> got(names.begin(), names.end());
  const std::set<std::string> want{
      "ViewLayer.Depth.Z",   "ViewLayer.Normal.X", "ViewLayer.Normal.Y", "ViewLayer.Normal.Z",
      "ViewLayer.AO.R",      "ViewLayer.AO.G",     "ViewLayer.AO.B",     "ViewLayer.DiffCol.R",
      "ViewLayer.DiffCol.G", "ViewLayer.DiffCol.B"};
  EXPECT_EQ(got, want);
  EXPECT_EQ(load_gbuffer(path("scene.exr")).channels, names);
}

TEST_F(ImageIo, AbsentPassesAreNotWrittenAndLoadAsEmpty) {
  TestGBuffer t;
  GBuffer depth_only = t.g;
  depth_only.normal = {};
  depth_only.color = {};
  save_gbuffer(path("d.exr"), depth_only, {}, "");
  EXPECT_EQ(exr_channel_names(path("d.exr")), std::vector<std::string>{"ViewLayer.Depth.Z"});
  const GBufferData d = load_gbuffer(path("d.exr"));
  EXPECT_TRUE(d.normal.pixels().empty());
  EXPECT_TRUE(d.color.pixels().empty());
  EXPECT_TRUE(d.ao.pixels().empty());
  EXPECT_FALSE(d.view().has_normal());
  EXPECT_FALSE(d.view().has_color());
}

TEST_F(ImageIo, CustomViewLayerIsWrittenAndFound) {
  TestGBuffer t;
  save_gbuffer(path("layer.exr"), t.g, {}, "{}", "My Layer.001");
  const std::vector<std::string> names = exr_channel_names(path("layer.exr"));
  EXPECT_NE(std::find(names.begin(), names.end(), "My Layer.001.Depth.Z"), names.end());
  // Found without a name (the first layer with Depth.Z; the layer name contains a dot) ...
  const GBufferData a = load_gbuffer(path("layer.exr"));
  EXPECT_EQ(a.normal.channels(), 3);
  EXPECT_EQ(a.depth(3, 2), t.depth(3, 2));
  // ... and by name.
  const GBufferData b = load_gbuffer(path("layer.exr"), "My Layer.001");
  EXPECT_EQ(b.depth(3, 2), t.depth(3, 2));
  // A layer that is not there names itself and lists the channels found.
  const std::string msg =
      testing::invalid_argument_message([&] { load_gbuffer(path("layer.exr"), "ViewLayer"); });
  EXPECT_NE(msg.find("ViewLayer.Depth.Z"), std::string::npos) << msg;
  EXPECT_NE(msg.find("My Layer.001.Normal.X"), std::string::npos) << msg;
}

TEST_F(ImageIo, WorldSpaceNormalsAreRotatedIntoViewSpace) {
  // A camera turned 90 degrees about x (Blender's default for a camera looking along +y),
  // then 30 degrees about z, scaled by 2 and moved: n_view = R^T n_world with R the
  // column-normalised 3x3.
  const double a = std::numbers::pi / 6.0, ca = std::cos(a), sa = std::sin(a);
  // Rz(30) * Rx(90): columns are the camera's x, y, z axes in world space.
  const double R[3][3] = {{ca, 0, sa}, {sa, 0, -ca}, {0, 1, 0}};
  std::string matrix = "[";
  for (int r = 0; r < 4; ++r) {
    matrix += r ? ", [" : "[";
    for (int c = 0; c < 4; ++c) {
      const double v = r == 3 ? (c == 3 ? 1.0 : 0.0) : c == 3 ? 1.5 * (r + 1) : 2.0 * R[r][c];
      matrix += (c ? ", " : "") + std::to_string(v);
    }
    matrix += "]";
  }
  matrix += "]";

  TestGBuffer t;  // its "view" normals are written as they are and relabelled world-space
  const std::string exr = path("world.exr");
  save_gbuffer(exr, t.g, {}, "{}");
  write_sidecar(sidecar_path_for(exr),
                R"({"width": 7, "height": 5, "fx": 6.5, "fy": 6.25, "cx": 3.5, "cy": 2.5,
                    "normal_space": "world", "camera_to_world": )" +
                    matrix + "}");
  const GBufferData d = load_gbuffer(exr);
  // std::to_string keeps 6 decimals of the matrix, so the rotation is exact to ~1e-6 and
  // the half-stored normals to kHalfTolerance.
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x)
      for (int i = 0; i < 3; ++i) {
        double want = 0;
        for (int j = 0; j < 3; ++j) want += R[j][i] * double(t.normal(x, y, j));
        EXPECT_NEAR(d.normal(x, y, i), want, kHalfTolerance) << x << ", " << y << ", " << i;
      }
  // Not renormalised or flipped here: the lengths are those stored (~1 within half).
  const float n0 = d.normal(3, 2, 0), n1 = d.normal(3, 2, 1), n2 = d.normal(3, 2, 2);
  EXPECT_NEAR(std::sqrt(n0 * n0 + n1 * n1 + n2 * n2), 1.0, kHalfTolerance);
}

TEST_F(ImageIo, WorldSpaceNormalsWithoutCameraToWorldAreAnError) {
  TestGBuffer t;
  const std::string exr = path("s.exr");
  save_gbuffer(exr, t.g, {}, "{}");
  write_sidecar(sidecar_path_for(exr),
                R"({"width": 7, "height": 5, "fx": 6.5, "fy": 6.25, "cx": 3.5, "cy": 2.5})");
  const std::string msg = testing::invalid_argument_message([&] { load_gbuffer(exr); });
  EXPECT_NE(msg.find("\"camera_to_world\""), std::string::npos) << msg;
  EXPECT_NE(msg.find("s.json"), std::string::npos) << msg;
}

TEST_F(ImageIo, SidecarOfAnotherSizeIsAnError) {
  TestGBuffer t;
  const std::string exr = path("s.exr");
  save_gbuffer(exr, t.g, {}, "{}");
  write_sidecar(sidecar_path_for(exr), R"({"width": 8, "height": 5, "fx": 6.5, "fy": 6.25,
                                           "cx": 3.5, "cy": 2.5, "normal_space": "view"})");
  const std::string msg = testing::invalid_argument_message([&] { load_gbuffer(exr); });
  EXPECT_NE(msg.find("8x5"), std::string::npos) << msg;
  EXPECT_NE(msg.find("7x5"), std::string::npos) << msg;
  EXPECT_NE(msg.find("s.json"), std::string::npos) << msg;
}

TEST_F(ImageIo, BadSidecarNamesTheKey) {
  TestGBuffer t;
  const std::string exr = path("s.exr");
  save_gbuffer(exr, t.g, {}, "{}");
  write_sidecar(sidecar_path_for(exr), R"({"width": 7, "height": 5, "fx": 6.5, "fy": 6.25,
                                           "cx": 3.5, "cy": 2.5, "normal_space": "view"})");
  // Corrupt it behind write_sidecar's back: drop "fy".
  {
    std::ofstream out(sidecar_path_for(exr));
    out << R"({"width": 7, "height": 5, "fx": 6.5, "cx": 3.5, "cy": 2.5})";
  }
  std::string msg = testing::invalid_argument_message([&] { load_gbuffer(exr); });
  EXPECT_NE(msg.find("\"fy\""), std::string::npos) << msg;
  {
    std::ofstream out(sidecar_path_for(exr));
    out << R"({"width": 7, "height": )";
  }
  msg = testing::invalid_argument_message([&] { load_gbuffer(exr); });
  EXPECT_NE(msg.find("not valid JSON"), std::string::npos) << msg;
}

TEST_F(ImageIo, MissingFilesThrowFileNotFound) {
  EXPECT_THROW(load_gbuffer(path("absent.exr")), FileNotFound);
  EXPECT_THROW(exr_channel_names(path("absent.exr")), FileNotFound);
  EXPECT_THROW(read_image(path("absent.png")), FileNotFound);
  try {
    load_gbuffer(path("absent.exr"));
  } catch (const FileNotFound& e) {
    EXPECT_EQ(e.path(), path("absent.exr"));
    EXPECT_NE(std::string(e.what()).find(path("absent.exr")), std::string::npos);
  }
  // The EXR is there but its sidecar is not.
  TestGBuffer t;
  save_gbuffer(path("s.exr"), t.g, {}, "{}");
  fs::remove(path("s.json"));
  try {
    load_gbuffer(path("s.exr"));
    FAIL() << "no exception";
  } catch (const FileNotFound& e) {
    EXPECT_EQ(e.path(), path("s.json"));
  }
  // Writing into a directory that does not exist.
  EXPECT_THROW(write_image(path("no/such/dir/ao.png"), t.ao.view()), FileNotFound);
}

TEST_F(ImageIo, MissingDepthListsTheChannelsFound) {
  Image rgb(4, 3, 3, 0.25f);
  write_image(path("plain.exr"), rgb.view());
  const std::string msg =
      testing::invalid_argument_message([&] { load_gbuffer(path("plain.exr")); });
  EXPECT_NE(msg.find(path("plain.exr")), std::string::npos) << msg;
  EXPECT_NE(msg.find("Depth.Z"), std::string::npos) << msg;
  EXPECT_NE(msg.find("[R, G, B]"), std::string::npos) << msg;
}

TEST_F(ImageIo, CorruptFileIsAnInvalidArgumentNamingThePath) {
  {
    std::ofstream out(path("junk.exr"), std::ios::binary);
    out << "this is not an OpenEXR file";
  }
  const std::string msg =
      testing::invalid_argument_message([&] { load_gbuffer(path("junk.exr")); });
  EXPECT_NE(msg.find(path("junk.exr")), std::string::npos) << msg;
}

TEST_F(ImageIo, UnprefixedChannelsAreAccepted) {
  // view_layer "" writes bare "Depth.Z", "Normal.X", ..., which the reader takes as a layer
  // named "", found without a name like any other.
  TestGBuffer t;
  save_gbuffer(path("bare.exr"), t.g, t.ao.view(), "{}", "");
  const std::vector<std::string> names = exr_channel_names(path("bare.exr"));
  EXPECT_NE(std::find(names.begin(), names.end(), "Depth.Z"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "Normal.Y"), names.end());
  const GBufferData d = load_gbuffer(path("bare.exr"));
  EXPECT_EQ(d.depth(4, 3), t.depth(4, 3));
  EXPECT_EQ(d.normal.channels(), 3);
  EXPECT_EQ(d.ao.channels(), 1);
}

TEST_F(ImageIo, ExrImageRoundTripIsFloat32) {
  Image ao(5, 4, 1);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 5; ++x) ao(x, y) = 0.123456789f * float(x) + 0.01f * float(y);
  write_image(path("ao.exr"), ao.view());
  EXPECT_EQ(exr_channel_names(path("ao.exr")), std::vector<std::string>{"Y"});
  const Image back = read_image(path("ao.exr"));
  ASSERT_EQ(back.channels(), 1);
  EXPECT_EQ(back.pixels(), ao.pixels());

  Image rgba(3, 2, 4, 0.75f);
  write_image(path("rgba.EXR"), rgba.view());  // the extension is case-insensitive
  EXPECT_EQ(exr_channel_names(path("rgba.EXR")), (std::vector<std::string>{"R", "G", "B", "A"}));
  EXPECT_EQ(read_image(path("rgba.EXR")).pixels(), rgba.pixels());
}

TEST_F(ImageIo, StridedViewIsWrittenRowByRow) {
  // A 3x2 window of a 5x4 image: the row stride is the parent's width.
  Image parent(5, 4, 1);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 5; ++x) parent(x, y) = float(10 * y + x);
  const ConstImageView window(&parent(1, 1), 3, 2, 1, 5);
  write_image(path("window.exr"), window);
  const Image back = read_image(path("window.exr"));
  EXPECT_EQ(back.pixels(), (Buffer<float>{11, 12, 13, 21, 22, 23}));
}

TEST_F(ImageIo, PngIsValueTimes255RoundedAndClamped) {
  const std::vector<float> values{0.0f, 0.5f, 1.0f, 1.7f, -0.2f, NAN, 0.25f, 0.9f};
  Image img(int(values.size()), 1, 1);
  img.pixels().assign(values.begin(), values.end());
  write_image(path("ao.png"), img.view());
  const Image back = read_image(path("ao.png"));
  ASSERT_EQ(back.width(), int(values.size()));
  ASSERT_EQ(back.channels(), 1);
  // OpenImageIO reads byte b as b / 255.
  const std::vector<int> want{0, 128, 255, 255, 0, 0, 64, 230};
  for (std::size_t i = 0; i < values.size(); ++i)
    EXPECT_EQ(int(std::lround(back.pixels()[i] * 255.0f)), want[i]) << "value " << values[i];
}

TEST_F(ImageIo, PngKeepsThreeAndFourChannels) {
  Image rgb(2, 2, 3);
  for (std::size_t i = 0; i < rgb.pixels().size(); ++i) rgb.pixels()[i] = float(i) / 11.0f;
  write_image(path("rgb.png"), rgb.view());
  const Image back = read_image(path("rgb.png"));
  ASSERT_EQ(back.channels(), 3);
  for (std::size_t i = 0; i < rgb.pixels().size(); ++i)
    EXPECT_NEAR(back.pixels()[i], rgb.pixels()[i], 0.5f / 255.0f + 1e-6f);
  Image rgba(2, 2, 4, 1.0f);
  write_image(path("rgba.png"), rgba.view());
  EXPECT_EQ(read_image(path("rgba.png")).channels(), 4);
}

TEST_F(ImageIo, BadArgumentsAreRejected) {
  Image img(3, 2, 1, 0.5f);
  std::string msg =
      testing::invalid_argument_message([&] { write_image(path("ao.tif"), img.view()); });
  EXPECT_NE(msg.find("must end in .exr or .png"), std::string::npos) << msg;
  EXPECT_NE(msg.find("ao.tif"), std::string::npos) << msg;
  Image two(3, 2, 2);
  msg = testing::invalid_argument_message([&] { write_image(path("ao.exr"), two.view()); });
  EXPECT_NE(msg.find("1, 3 or 4 channels"), std::string::npos) << msg;
  EXPECT_THROW(write_image(path("ao.png"), ConstImageView{}), std::invalid_argument);

  TestGBuffer t;
  Image small_ao(3, 2, 1);
  msg = testing::invalid_argument_message(
      [&] { save_gbuffer(path("g.exr"), t.g, small_ao.view(), "{}"); });
  EXPECT_NE(msg.find("reference"), std::string::npos) << msg;
  EXPECT_THROW(save_gbuffer(path("g.png"), t.g, {}, "{}"), std::invalid_argument);
  EXPECT_THROW(save_gbuffer(path("g.exr"), t.g, {}, "[]"), std::invalid_argument);
  GBuffer bad = t.g;
  bad.camera.fx = -1;
  EXPECT_THROW(save_gbuffer(path("g.exr"), bad, {}, "{}"), std::invalid_argument);
  // A sidecar value save_gbuffer would write but not read back is refused up front.
  EXPECT_THROW(save_gbuffer(path("g.exr"), t.g, {}, R"({"samples": -3})"), std::invalid_argument);
  EXPECT_TRUE(files().empty()) << "a rejected write left files behind";
}

TEST_F(ImageIo, AtomicWritesLeaveNoTemporaryFiles) {
  TestGBuffer t;
  write_image(path("a.png"), t.ao.view());
  write_image(path("a.exr"), t.ao.view());
  write_image(path("a.exr"), t.ao.view());  // replacing an existing file
  save_gbuffer(path("g.exr"), t.g, t.ao.view(), "{}");
  EXPECT_EQ(files(), (std::set<std::string>{"a.png", "a.exr", "g.exr", "g.json"}));

  EXPECT_EQ(read_image(path("a.exr")).pixels(), t.ao.pixels());
}

// Hostile inputs: a path that is not a regular file is refused before it is opened (a FIFO
// would block the reader forever).
TEST_F(ImageIo, NonRegularFilesAreRefusedByKind) {
  const std::string fifo = path("x.exr");
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  std::string msg = testing::invalid_argument_message([&] { load_gbuffer(fifo); });
  EXPECT_NE(msg.find(fifo), std::string::npos) << msg;
  EXPECT_NE(msg.find("FIFO"), std::string::npos) << msg;
  fs::create_directory(path("d.exr"));
  msg = testing::invalid_argument_message([&] { load_gbuffer(path("d.exr")); });
  EXPECT_NE(msg.find("directory"), std::string::npos) << msg;
  msg = testing::invalid_argument_message([&] { read_image("/dev/null"); });
  EXPECT_NE(msg.find("character device"), std::string::npos) << msg;
  // The sidecar too.
  TestGBuffer t;
  save_gbuffer(path("g.exr"), t.g, {}, "");
  fs::remove(path("g.json"));
  ASSERT_EQ(mkfifo(path("g.json").c_str(), 0600), 0);
  msg = testing::invalid_argument_message([&] { load_gbuffer(path("g.exr")); });
  EXPECT_NE(msg.find("g.json"), std::string::npos) << msg;
  EXPECT_NE(msg.find("FIFO"), std::string::npos) << msg;
}

}  // namespace
}  // namespace aolab
