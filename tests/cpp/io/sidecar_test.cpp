// The camera sidecar: schema defaults, validation errors that name the key and the file,
// atomic writes and the text save_gbuffer writes.
#include "core/io/sidecar.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "core/io/image_io.h"
#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

namespace fs = std::filesystem;

const char* kMinimal = R"({"width": 7, "height": 5, "fx": 6.5, "fy": 6.5, "cx": 3.5, "cy": 2.5})";

// The message of the std::invalid_argument that `f` throws ("" if it throws nothing).
template <class F>
std::string invalid_message(F f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

std::string read_file(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

using SidecarFiles = testing::TempDirTest;

TEST(Sidecar, PathHasTheStemOfTheExr) {
  EXPECT_EQ(sidecar_path_for("renders/scene.exr"), fs::path("renders/scene.json").string());
  EXPECT_EQ(sidecar_path_for("a.b.exr"), "a.b.json");
  EXPECT_EQ(sidecar_path_for("scene"), "scene.json");
}

TEST(Sidecar, MinimalDocumentGetsTheDocumentedDefaults) {
  const CameraSidecar s = parse_sidecar(kMinimal, "mem.json");
  EXPECT_EQ(s.width, 7);
  EXPECT_EQ(s.height, 5);
  EXPECT_EQ(s.fx, 6.5);
  EXPECT_EQ(s.cy, 2.5);
  EXPECT_FALSE(s.has_camera_to_world);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      EXPECT_EQ(s.camera_to_world[std::size_t(4 * r + c)], r == c ? 1.0 : 0.0);
  EXPECT_TRUE(std::isnan(s.ao_distance));
  EXPECT_EQ(s.samples, 0);
  EXPECT_EQ(s.background_depth, kDefaultBackgroundDepth);
  EXPECT_EQ(s.normal_space, "world");  // what Blender's Normal pass holds
  EXPECT_EQ(s.json_text, kMinimal);
  const CameraIntrinsics k = s.intrinsics();
  EXPECT_EQ(k.fx, 6.5f);
  EXPECT_EQ(k.cx, 3.5f);
}

TEST(Sidecar, FullDocumentIsReadAndUnknownKeysAreKept) {
  const std::string text = R"({
    "width": 640, "height": 360, "fx": 700.25, "fy": 701.5, "cx": 320, "cy": 180.5,
    "camera_to_world": [[1, 0, 0, 5], [0, 0, -1, -6], [0, 1, 0, 2], [0, 0, 0, 1]],
    "ao_distance": 1.25, "samples": 1024, "background_depth": 65504,
    "normal_space": "view", "clip_start": 0.1, "render": {"engine": "CYCLES"}})";
  const CameraSidecar s = parse_sidecar(text, "scene.json");
  EXPECT_EQ(s.width, 640);
  EXPECT_EQ(s.cx, 320.0);
  EXPECT_TRUE(s.has_camera_to_world);
  EXPECT_EQ(s.camera_to_world[3], 5.0);   // row 0, column 3: row-major
  EXPECT_EQ(s.camera_to_world[6], -1.0);  // row 1, column 2
  EXPECT_EQ(s.camera_to_world[9], 1.0);   // row 2, column 1
  EXPECT_EQ(s.ao_distance, 1.25);
  EXPECT_EQ(s.samples, 1024);
  EXPECT_EQ(s.background_depth, 65504.0f);
  EXPECT_EQ(s.normal_space, "view");
  EXPECT_NE(s.json_text.find("\"clip_start\""), std::string::npos);
  EXPECT_NE(s.json_text.find("CYCLES"), std::string::npos);
}

TEST(Sidecar, NullOptionalKeysMeanAbsent) {
  const CameraSidecar s = parse_sidecar(
      R"({"width": 7, "height": 5, "fx": 6.5, "fy": 6.5, "cx": 3.5, "cy": 2.5,
          "ao_distance": null, "camera_to_world": null, "samples": null})",
      "mem.json");
  EXPECT_TRUE(std::isnan(s.ao_distance));
  EXPECT_FALSE(s.has_camera_to_world);
  EXPECT_EQ(s.samples, 0);
}

TEST(Sidecar, MissingRequiredKeyNamesTheKeyAndTheFile) {
  for (const char* key : {"width", "height", "fx", "fy", "cx", "cy"}) {
    std::string text = kMinimal;
    const std::string quoted = std::string("\"") + key + "\"";
    // Rename the key so the document stays valid JSON but lacks it.
    text.replace(text.find(quoted), quoted.size(), "\"unused\"");
    const std::string msg = invalid_message([&] { parse_sidecar(text, "/renders/scene.json"); });
    EXPECT_NE(msg.find(quoted), std::string::npos) << msg;
    EXPECT_NE(msg.find("/renders/scene.json"), std::string::npos) << msg;
    EXPECT_NE(msg.find("required"), std::string::npos) << msg;
  }
}

struct BadValue {
  const char* document;
  const char* key;
  const char* requirement;
};

class SidecarBadValue : public ::testing::TestWithParam<BadValue> {};

TEST_P(SidecarBadValue, ErrorNamesKeyFileAndValue) {
  const BadValue& bad = GetParam();
  const std::string msg = invalid_message([&] { parse_sidecar(bad.document, "cam.json"); });
  ASSERT_FALSE(msg.empty()) << bad.document;
  EXPECT_NE(msg.find(std::string("\"") + bad.key + "\""), std::string::npos) << msg;
  EXPECT_NE(msg.find("cam.json"), std::string::npos) << msg;
  EXPECT_NE(msg.find(bad.requirement), std::string::npos) << msg;
}

INSTANTIATE_TEST_SUITE_P(
    Values, SidecarBadValue,
    ::testing::Values(
        BadValue{R"({"width": "7", "height": 5, "fx": 1, "fy": 1, "cx": 0, "cy": 0})", "width",
                 "must be an integer"},
        BadValue{R"({"width": 7.0, "height": 5, "fx": 1, "fy": 1, "cx": 0, "cy": 0})", "width",
                 "must be an integer"},
        BadValue{R"({"width": 7, "height": 0, "fx": 1, "fy": 1, "cx": 0, "cy": 0})", "height",
                 ">= 1"},
        BadValue{R"({"width": 7, "height": 5, "fx": "abc", "fy": 1, "cx": 0, "cy": 0})", "fx",
                 "must be a number"},
        BadValue{R"({"width": 7, "height": 5, "fx": 1, "fy": -2, "cx": 0, "cy": 0})", "fy",
                 "must be > 0"},
        BadValue{R"({"width": 7, "height": 5, "fx": 1, "fy": 1, "cx": true, "cy": 0})", "cx",
                 "must be a number"},
        BadValue{R"({"width": 7, "height": 5, "fx": 1, "fy": 1, "cx": 0, "cy": 0,
                     "samples": -1})",
                 "samples", ">= 0"},
        BadValue{R"({"width": 7, "height": 5, "fx": 1, "fy": 1, "cx": 0, "cy": 0,
                     "ao_distance": 0})",
                 "ao_distance", "must be > 0"},
        BadValue{R"({"width": 7, "height": 5, "fx": 1, "fy": 1, "cx": 0, "cy": 0,
                     "background_depth": 1e300})",
                 "background_depth", "must fit in a float"},
        BadValue{R"({"width": 7, "height": 5, "fx": 1, "fy": 1, "cx": 0, "cy": 0,
                     "normal_space": "camera"})",
                 "normal_space", "\"view\" or \"world\""},
        BadValue{R"({"width": 7, "height": 5, "fx": 1, "fy": 1, "cx": 0, "cy": 0,
                     "camera_to_world": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]})",
                 "camera_to_world", "4x4"},
        BadValue{R"({"width": 7, "height": 5, "fx": 1, "fy": 1, "cx": 0, "cy": 0,
                     "camera_to_world": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]})",
                 "camera_to_world", "4x4"},
        BadValue{R"({"width": 7, "height": 5, "fx": 1, "fy": 1, "cx": 0, "cy": 0,
                     "camera_to_world": [[0, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]})",
                 "camera_to_world", "non-zero axis"}),
    [](const ::testing::TestParamInfo<BadValue>& param_info) {
      return std::string(param_info.param.key) + "_" + std::to_string(param_info.index);
    });

TEST(Sidecar, InvalidJsonIncludesTheParserMessage) {
  const std::string msg = invalid_message([] { parse_sidecar(R"({"width": 7,)", "bad.json"); });
  EXPECT_NE(msg.find("bad.json"), std::string::npos) << msg;
  EXPECT_NE(msg.find("not valid JSON"), std::string::npos) << msg;
  EXPECT_NE(msg.find("parse error"), std::string::npos) << msg;  // nlohmann's own words
}

TEST(Sidecar, NonFiniteNumberIsRejected) {
  // JSON has no inf or NaN; a number that overflows a double is the only way to write one.
  const std::string msg = invalid_message([] {
    parse_sidecar(R"({"width": 7, "height": 5, "fx": 1e999, "fy": 1, "cx": 0, "cy": 0})",
                  "inf.json");
  });
  EXPECT_NE(msg.find("inf.json"), std::string::npos) << msg;
  EXPECT_NE(msg.find("1e999"), std::string::npos) << msg;
}

TEST(Sidecar, DocumentMustBeAnObject) {
  const std::string msg = invalid_message([] { parse_sidecar("[1, 2]", "list.json"); });
  EXPECT_NE(msg.find("must be a JSON object"), std::string::npos) << msg;
  EXPECT_NE(msg.find("got array"), std::string::npos) << msg;
}

TEST_F(SidecarFiles, WriteThenReadKeepsEveryKey) {
  const fs::path path = dir_ / "scene.json";
  const std::string text =
      R"({"width": 7, "height": 5, "fx": 6.5, "fy": 6.5, "cx": 3.5, "cy": 2.5, "hash": "abc"})";
  write_sidecar(path.string(), text);
  const CameraSidecar s = read_sidecar(path.string());
  EXPECT_EQ(s.width, 7);
  EXPECT_NE(s.json_text.find("\"hash\": \"abc\""), std::string::npos);
  // Only the sidecar itself: the temporary file was renamed, not left behind.
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir_)) {
    ++files;
    EXPECT_EQ(e.path().filename(), "scene.json");
  }
  EXPECT_EQ(files, 1);
}

TEST_F(SidecarFiles, WriteRefusesAnInvalidSidecarAndKeepsTheOldFile) {
  const fs::path path = dir_ / "scene.json";
  write_sidecar(path.string(), kMinimal);
  const std::string msg =
      invalid_message([&] { write_sidecar(path.string(), R"({"width": 7, "height": 5})"); });
  EXPECT_NE(msg.find("\"fx\""), std::string::npos) << msg;
  EXPECT_EQ(read_file(path), std::string(kMinimal) + "\n");
}

TEST_F(SidecarFiles, MissingFileThrowsFileNotFound) {
  const std::string path = (dir_ / "absent.json").string();
  try {
    read_sidecar(path);
    FAIL() << "no exception";
  } catch (const FileNotFound& e) {
    EXPECT_EQ(e.path(), path);
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos);
  }
}

TEST_F(SidecarFiles, MissingDirectoryThrowsFileNotFound) {
  EXPECT_THROW(write_sidecar((dir_ / "no" / "such" / "scene.json").string(), kMinimal),
               FileNotFound);
}

TEST(Sidecar, JsonForAGBufferSetsItsCameraAndKeepsOtherKeys) {
  const float depth[2 * 3] = {1, 2, 3, 4, 5, 6};
  GBuffer g;
  g.depth = ConstImageView(depth, 3, 2);
  g.camera = {123.4f, 120.1f, 1.5f, 1.0f};
  g.background_depth = 65504.0f;
  const std::string text = sidecar_json_for(
      g, R"({"fx": 1, "normal_space": "world", "ao_distance": 2.5, "note": "kept"})");
  const CameraSidecar s = parse_sidecar(text, "out.json");
  EXPECT_EQ(s.width, 3);
  EXPECT_EQ(s.height, 2);
  EXPECT_EQ(float(s.fx), 123.4f);  // exactly the same float after the round trip
  EXPECT_EQ(float(s.fy), 120.1f);
  EXPECT_EQ(s.background_depth, 65504.0f);
  EXPECT_EQ(s.normal_space, "view");  // G-buffer normals are view-space
  EXPECT_EQ(s.ao_distance, 2.5);
  EXPECT_NE(text.find("\"note\": \"kept\""), std::string::npos);
  EXPECT_NE(text.find("123.4,"), std::string::npos)
      << text;                                            // shortest decimal, not 123.40000152...
  EXPECT_LT(text.find("\"fx\""), text.find("\"note\""));  // the given key order is kept
  EXPECT_THROW(sidecar_json_for(g, "[1]"), std::invalid_argument);
  EXPECT_EQ(parse_sidecar(sidecar_json_for(g, ""), "empty.json").width, 3);
}

// Hostile inputs (the issue "Hostile inputs"): each gives a message naming the file.
TEST(SidecarHostile, Latin1ByteNamesTheFileAndTheEncoding) {
  const std::string text = R"({"width": 7, "height": 5, "fx": 6.5, "fy": 6.5, "cx": 3.5,)"
                           " \"cy\": 2.5, \"note\": \"caf\xE9\"}";
  const std::string msg = invalid_message([&] { parse_sidecar(text, "latin.json"); });
  EXPECT_NE(msg.find("latin.json"), std::string::npos) << msg;
  EXPECT_NE(msg.find("UTF-8"), std::string::npos) << msg;
  EXPECT_NE(msg.find("0xE9"), std::string::npos) << msg;
  // The message itself is valid UTF-8 (it reaches Python as a str).
  for (unsigned char c : msg) EXPECT_LT(c, 0x80) << msg;
}

TEST(SidecarHostile, ByteOrderMarkIsAcceptedAndDropped) {
  const CameraSidecar s = parse_sidecar(std::string("\xEF\xBB\xBF") + kMinimal, "bom.json");
  EXPECT_EQ(s.width, 7);
  EXPECT_EQ(s.json_text, kMinimal);
}

TEST(SidecarHostile, NullRequiredKeyIsCalledNullNotMissing) {
  const std::string msg = invalid_message([] {
    parse_sidecar(R"({"width": 7, "height": 5, "fx": null, "fy": 6.5, "cx": 3.5, "cy": 2.5})",
                  "null.json");
  });
  EXPECT_NE(msg.find("\"fx\""), std::string::npos) << msg;
  EXPECT_NE(msg.find("null.json"), std::string::npos) << msg;
  EXPECT_NE(msg.find("got null"), std::string::npos) << msg;
  EXPECT_EQ(msg.find("must have the required key"), std::string::npos) << msg;
}

TEST(SidecarHostile, FocalLengthThatRoundsToZeroInAFloatIsRefusedAsWritten) {
  std::string msg = invalid_message([] {
    parse_sidecar(R"({"width": 7, "height": 5, "fx": 1e-50, "fy": 6.5, "cx": 3.5, "cy": 2.5})",
                  "tiny.json");
  });
  EXPECT_NE(msg.find("tiny.json"), std::string::npos) << msg;
  EXPECT_NE(msg.find("\"fx\""), std::string::npos) << msg;
  EXPECT_NE(msg.find("got 1e-50"), std::string::npos) << msg;
  msg = invalid_message([] {
    parse_sidecar(R"({"width": 7, "height": 5, "fx": 6.5, "fy": 6.5, "cx": 1e300, "cy": 2.5})",
                  "huge.json");
  });
  EXPECT_NE(msg.find("\"cx\""), std::string::npos) << msg;
  EXPECT_NE(msg.find("got 1e+300"), std::string::npos) << msg;
}

TEST(SidecarHostile, DeepNestingIsRefusedBeforeParsing) {
  const std::string deep(100000, '[');
  std::string msg = invalid_message([&] { parse_sidecar(deep, "deep.json"); });
  EXPECT_NE(msg.find("deep.json"), std::string::npos) << msg;
  EXPECT_NE(msg.find("64"), std::string::npos) << msg;
  // 64 levels inside an extra key are fine; brackets inside strings do not count.
  std::string ok = R"({"width": 7, "height": 5, "fx": 6.5, "fy": 6.5, "cx": 3.5, "cy": 2.5, "x": )";
  ok += std::string(63, '[') + std::string(63, ']') + R"(, "s": "[[[[[[[[\"[[[[[[[[[[[[[[[[[[[["})";
  EXPECT_EQ(parse_sidecar(ok, "ok.json").width, 7);
}

}  // namespace
}  // namespace aolab
