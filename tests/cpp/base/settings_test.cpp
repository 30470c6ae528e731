#include "core/base/settings.h"

#include <gtest/gtest.h>

#include "core/filters/blur.h"
#include "core/methods/hbao/hbao.h"
#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

TEST(Settings, FromValuesSetsAndValidates) {
  const auto s = settings_from_values<HbaoSettings>(
      {{"radius", 2.5}, {"directions", 16}, {"jitter", 0}}, kHbaoFields, "hbao");
  EXPECT_EQ(s.radius, 2.5f);
  EXPECT_EQ(s.directions, 16);
  EXPECT_FALSE(s.jitter);
  EXPECT_EQ(s.steps, kHbaoDefaultSteps);
}

TEST(Settings, ErrorsNameParameterAndValue) {
  auto msg = testing::invalid_argument_message([] {
    settings_from_values<HbaoSettings>({{"directions", 0}}, kHbaoFields, "hbao");
  });
  EXPECT_NE(msg.find("directions"), std::string::npos) << msg;
  EXPECT_NE(msg.find("got 0"), std::string::npos) << msg;
  msg = testing::invalid_argument_message([] {
    settings_from_values<HbaoSettings>({{"steps", 2.5}}, kHbaoFields, "hbao");
  });
  EXPECT_NE(msg.find("integer"), std::string::npos) << msg;
  msg = testing::invalid_argument_message([] {
    settings_from_values<HbaoSettings>({{"jitter", 3}}, kHbaoFields, "hbao");
  });
  EXPECT_NE(msg.find("boolean"), std::string::npos) << msg;
  msg = testing::invalid_argument_message([] {
    settings_from_values<HbaoSettings>({{"radius", -1}}, kHbaoFields, "hbao");
  });
  EXPECT_NE(msg.find("radius"), std::string::npos) << msg;
  msg = testing::invalid_argument_message([] {
    settings_from_values<HbaoSettings>({{"bogus", 1}}, kHbaoFields, "hbao");
  });
  EXPECT_NE(msg.find("bogus"), std::string::npos) << msg;
  EXPECT_NE(msg.find("directions"), std::string::npos) << msg;  // lists the valid names
}

TEST(Settings, DescribeHasDefaultsAndRanges) {
  const auto d = describe_settings(kHbaoFields);
  ASSERT_EQ(d.size(), std::size(kHbaoFields));
  EXPECT_EQ(d[1].name, "directions");
  EXPECT_EQ(d[1].type, SettingType::Int);
  EXPECT_EQ(d[1].default_value, kHbaoDefaultDirections);
  EXPECT_EQ(d[3].type, SettingType::Bool);
  // Every default is inside its own range.
  for (const auto& s : d) {
    EXPECT_GE(s.default_value, s.min) << s.name;
    EXPECT_LE(s.default_value, s.max) << s.name;
    EXPECT_FALSE(s.description.empty()) << s.name;
  }
}

}  // namespace
}  // namespace aolab
