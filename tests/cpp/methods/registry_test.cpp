// The registry's own setting, `power` (AO^power after the method, applied once in compute()
// for every method): described for every method, bit-identical at 1, exactly ao·ao at 2,
// pow in double rounded once otherwise, per channel, background kept at 1, out-of-range values
// rejected by name.
#include "core/methods/registry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::invalid_argument_message;
using testing::SceneFixture;

TEST(RegistryPower, IsDescribedOnceForEveryMethod) {
  for (const Method& m : methods()) {
    int rows = 0;
    for (const SettingDescription& d : m.settings) {
      if (d.name != "power") continue;
      ++rows;
      EXPECT_EQ(int(d.type), int(SettingType::Float)) << m.name;
      EXPECT_EQ(d.default_value, 1.0) << m.name;
      EXPECT_EQ(d.min, kPowerMin) << m.name;
      EXPECT_EQ(d.max, kPowerMax) << m.name;
      EXPECT_EQ(d.unit, "") << m.name;
      EXPECT_FALSE(d.description.empty()) << m.name;
    }
    EXPECT_EQ(rows, 1) << m.name;
  }
}

// A scene with a band of background, so that "background stays 1" is checked too.
struct PowerScene : SceneFixture {
  PowerScene() : SceneFixture("blocks", 64, 36) {
    for (int y = 0; y < 36; ++y)
      for (int x = 0; x < 6; ++x) scene.depth(x, y) = INFINITY;
  }
};

TEST(RegistryPower, OneIsBitIdenticalAndTwoIsTheSquare) {
  const PowerScene f;
  for (const Method& m : methods()) {
    const SettingValues base{{"radius", 1.0}};
    const Image plain = compute(m.name, f.g, base);
    SettingValues one = base, two = base, half = base;
    one["power"] = 1.0, two["power"] = 2.0, half["power"] = 0.5;
    EXPECT_EQ(compute(m.name, f.g, one).pixels(), plain.pixels()) << m.name;
    const Image squared = compute(m.name, f.g, two), rooted = compute(m.name, f.g, half);
    bool occluded = false;
    for (std::size_t i = 0; i < plain.pixels().size(); ++i) {
      const float a = plain.pixels()[i];
      occluded |= a < 1.0f;
      ASSERT_EQ(squared.pixels()[i], a * a) << m.name << " pixel " << i;
      ASSERT_EQ(rooted.pixels()[i], float(std::sqrt(double(a)))) << m.name << " pixel " << i;
    }
    EXPECT_TRUE(occluded) << m.name << ": the scene must give something to square";
    for (int y = 0; y < 36; ++y)
      for (int x = 0; x < 6; ++x) {
        ASSERT_EQ(squared(x, y), 1.0f) << m.name;
        ASSERT_EQ(rooted(x, y), 1.0f) << m.name;
      }
  }
}

// An RGB result (vao_pp's colour bleeding) is raised per channel.
TEST(RegistryPower, AppliesPerChannel) {
  PowerScene f;
  Image color(64, 36, 3, 0.5f);
  f.g.color = color.view();
  const SettingValues base{{"radius", 1.0}, {"color_bleeding", 1}};
  SettingValues two = base;
  two["power"] = 2.0;
  const Image plain = compute("vao_pp", f.g, base), squared = compute("vao_pp", f.g, two);
  ASSERT_EQ(plain.channels(), 3);
  ASSERT_EQ(squared.channels(), 3);
  for (std::size_t i = 0; i < plain.pixels().size(); ++i)
    ASSERT_EQ(squared.pixels()[i], plain.pixels()[i] * plain.pixels()[i]) << i;
}

TEST(RegistryPower, OutOfRangeIsRejectedNamingIt) {
  const SceneFixture f("plane", 16, 9);
  for (const Method& m : methods())
    for (double p : {0.0, 0.05, 10.5, -2.0, double(NAN), double(INFINITY)}) {
      const std::string message = invalid_argument_message([&] {
        compute(m.name, f.g, {{"radius", 1.0}, {"power", p}});
      });
      EXPECT_EQ(message.rfind("power must be in [0.1, 10], got ", 0), 0u)
          << m.name << " power " << p << ": '" << message << "'";
    }
}

// The method's own table never sees `power`: compute() takes it out, and a method's field
// table has no such row; an unknown name's message still lists it as valid.
TEST(RegistryPower, IsNotAMethodField) {
  const SceneFixture f("plane", 16, 9);
  for (const Method& m : methods()) {
    const std::string message = invalid_argument_message([&] {
      compute(m.name, f.g, {{"radius", 1.0}, {"bogus", 1}});
    });
    EXPECT_NE(message.find("unknown setting 'bogus' for " + m.name), std::string::npos) << message;
    EXPECT_NE(message.find(", power"), std::string::npos) << message;
    EXPECT_EQ(invalid_argument_message([&] {
                compute(m.name, f.g, {{"radius", 1.0}, {"power", kPowerMax}});
              }),
              "")
        << m.name;
  }
}

}  // namespace
}  // namespace aolab
