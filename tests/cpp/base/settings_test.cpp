#include "core/base/settings.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "core/filters/blur.h"
#include "core/methods/hbao/hbao.h"
#include "core/methods/registry.h"
#include "core/methods/vao_pp/vao_pp.h"
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

TEST(Settings, ChoicesAreNamedInTheirDescription) {
  const auto d = describe_settings(kVaoPpFields);
  const auto culling =
      std::find_if(d.begin(), d.end(), [](const auto& s) { return s.name == "culling"; });
  ASSERT_NE(culling, d.end());
  EXPECT_EQ(culling->type, SettingType::Choice);
  EXPECT_EQ(culling->choices, (std::vector<std::string>{"off", "greedy", "careful"}));
  EXPECT_EQ(culling->default_value, double(VaoPpCulling::Careful));
  EXPECT_EQ(choice_value(*culling, "off"), double(VaoPpCulling::Off));
  EXPECT_EQ(choice_value(*culling, "careful"), double(VaoPpCulling::Careful));
  const auto msg = testing::invalid_argument_message([&] { choice_value(*culling, "lazy"); });
  EXPECT_NE(msg.find("culling"), std::string::npos) << msg;
  EXPECT_NE(msg.find("off, greedy, careful"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'lazy'"), std::string::npos) << msg;
}

TEST(Settings, OutOfRangeChoiceListsTheNames) {
  const auto msg = testing::invalid_argument_message([] {
    settings_from_values<VaoPpSettings>({{"culling", 3}}, kVaoPpFields, "vao_pp");
  });
  EXPECT_NE(msg.find("one of off, greedy, careful"), std::string::npos) << msg;
}

TEST(Settings, EveryChoiceCoversItsRangeAndEveryDefaultIsInside) {
  for (const auto& m : methods()) {
    for (const auto& s : m.settings) {
      EXPECT_GE(s.default_value, s.min) << m.name << "." << s.name;
      EXPECT_LE(s.default_value, s.max) << m.name << "." << s.name;
      if (s.type != SettingType::Choice) continue;
      EXPECT_EQ(double(s.choices.size()), s.max - s.min + 1) << m.name << "." << s.name;
      for (std::size_t i = 0; i < s.choices.size(); ++i)
        EXPECT_EQ(choice_value(s, s.choices[i]), s.min + double(i)) << s.choices[i];
    }
  }
}

}  // namespace
}  // namespace aolab
