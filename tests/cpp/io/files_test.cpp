// Durable writes (core/io/files.h): the target is replaced by the complete new bytes or left
// as it was, no temporary file survives, and a full disk is an error, never an empty file.
// The full-disk cases run on a small tmpfs mounted for the test (root only; skipped with the
// reason otherwise).
#include "core/io/files.h"

#include <gtest/gtest.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>

#include "core/io/image_io.h"
#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

namespace fs = std::filesystem;

std::string contents(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class Files : public testing::TempDirTest {
 protected:
  std::set<std::string> names() const {
    std::set<std::string> s;
    for (const auto& e : fs::directory_iterator(dir_)) s.insert(e.path().filename().string());
    return s;
  }
};

TEST_F(Files, WritesAndReplacesWholeFiles) {
  write_file_durably(path("a.txt"), "first");
  write_file_durably(path("a.txt"), "second, longer");
  EXPECT_EQ(contents(path("a.txt")), "second, longer");
  write_file_durably(path("empty"), "");  // an empty file is a legitimate result
  EXPECT_EQ(contents(path("empty")), "");
  EXPECT_EQ(names(), (std::set<std::string>{"a.txt", "empty"}));
}

TEST_F(Files, RefusesWhatItMustNotReplace) {
  fs::create_directory(path("dir"));
  EXPECT_THROW(write_file_durably(path("dir"), "x"), std::invalid_argument);
  ASSERT_EQ(::mkfifo(path("fifo").c_str(), 0600), 0);
  EXPECT_THROW(write_file_durably(path("fifo"), "x"), std::invalid_argument);
  EXPECT_THROW(write_file_durably(path("missing/a.txt"), "x"), FileNotFound);
  EXPECT_EQ(names(), (std::set<std::string>{"dir", "fifo"}));
}

TEST_F(Files, AFailedWriteLeavesTheTargetAndNoTemporary) {
  write_file_durably(path("a.txt"), "good");
  ::chmod(dir_.c_str(), 0500);  // no new files in the directory
  if (::access(dir_.c_str(), W_OK) == 0) {
    ::chmod(dir_.c_str(), 0700);
    GTEST_SKIP() << "running as root: a read-only directory does not stop root's writes";
  }
  EXPECT_THROW(write_file_durably(path("a.txt"), "bad"), WriteFailed);
  ::chmod(dir_.c_str(), 0700);
  EXPECT_EQ(contents(path("a.txt")), "good");
  EXPECT_EQ(names(), (std::set<std::string>{"a.txt"}));
}

// A 64 KiB tmpfs, filled by the test: the real ENOSPC of a full disk.
class FullDisk : public testing::TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    mount_ = dir_ / "small";
    fs::create_directory(mount_);
    if (::mount("tmpfs", mount_.c_str(), "tmpfs", 0, "size=64k") != 0)
      GTEST_SKIP() << "cannot mount a small tmpfs for the full-disk test (" << std::strerror(errno)
                   << "; needs root)";
    mounted_ = true;
  }
  void TearDown() override {
    if (mounted_) ::umount(mount_.c_str());
    TempDirTest::TearDown();
  }
  // Fills the file system up to its last byte.
  void fill() {
    std::ofstream f(mount_ / "filler", std::ios::binary);
    const std::string block(4096, 'x');
    while (f.write(block.data(), std::streamsize(block.size()))) {
    }
  }
  std::string in(const std::string& name) const { return (mount_ / name).string(); }
  fs::path mount_;
  bool mounted_ = false;
};

TEST_F(FullDisk, IsAnErrorThatKeepsTheEarlierFile) {
  write_file_durably(in("a.txt"), "the good result");
  fill();
  EXPECT_THROW(write_file_durably(in("a.txt"), std::string(100000, 'y')), WriteFailed);
  EXPECT_EQ(contents(in("a.txt")), "the good result");
  for (const auto& e : fs::directory_iterator(mount_))
    EXPECT_TRUE(e.path().filename() == "a.txt" || e.path().filename() == "filler")
        << "left behind: " << e.path();
}

TEST_F(FullDisk, ImagesAndGBuffersAreNotReplacedByEmptyFiles) {
  Image image(64, 64, 1);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) image(x, y) = float((x * 7 + y * 13) % 64) / 64.0f;
  write_image(in("ao.exr"), image.view());
  write_image(in("ao.png"), image.view());
  const auto exr_size = fs::file_size(in("ao.exr"));
  fill();
  Image other(256, 256, 1);  // another image, larger than what is left
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x) other(x, y) = float((x * 31 + y * 17) % 97) / 97.0f;
  EXPECT_THROW(write_image(in("ao.exr"), other.view()), WriteFailed);
  EXPECT_THROW(write_image(in("ao.png"), other.view()), WriteFailed);
  EXPECT_EQ(fs::file_size(in("ao.exr")), exr_size);
  EXPECT_EQ(read_image(in("ao.exr")).pixels(), image.pixels());
  EXPECT_EQ(std::distance(fs::directory_iterator(mount_), fs::directory_iterator()), 3);
}

TEST_F(FullDisk, AGBufferAndItsSidecarStayAPair) {
  Image depth(32, 32, 1);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) depth(x, y) = 1.0f + 0.01f * float(x + y);
  GBuffer g;
  g.depth = depth.view();
  g.camera = CameraIntrinsics{30.0f, 30.0f, 16.0f, 16.0f};
  save_gbuffer(in("g.exr"), g, {}, R"({"ao_distance": 0.5})");
  const std::string exr = contents(in("g.exr")), json = contents(in("g.json"));
  fill();
  // The new sidecar alone would fit; the pair does not: neither may change.
  Image big_depth(256, 256, 1);
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x) big_depth(x, y) = 1.0f + 0.001f * float((x * 37 + y) % 101);
  g.depth = big_depth.view();
  g.camera = CameraIntrinsics{300.0f, 300.0f, 128.0f, 128.0f};
  EXPECT_THROW(save_gbuffer(in("g.exr"), g, {}, R"({"ao_distance": 2})"), WriteFailed);
  EXPECT_EQ(contents(in("g.exr")), exr);
  EXPECT_EQ(contents(in("g.json")), json);
}

}  // namespace
}  // namespace aolab
