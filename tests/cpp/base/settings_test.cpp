#include "core/base/settings.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
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

// Hostile inputs: an out-of-range value and its bound print with every digit, so that 2^31
// (one past seed's maximum) is not shown as 2.14748e+09 beside a maximum of 2.14748e+09.
TEST(Settings, OutOfRangeMessagesPrintValueAndBoundExactly) {
  auto msg = testing::invalid_argument_message([] {
    settings_from_values<HbaoSettings>({{"seed", 2147483648.0}}, kHbaoFields, "hbao");
  });
  EXPECT_NE(msg.find("[0, 2147483647]"), std::string::npos) << msg;
  EXPECT_NE(msg.find("got 2147483648"), std::string::npos) << msg;
  EXPECT_EQ(msg.find("e+09"), std::string::npos) << msg;
  // A float just above a bound keeps the digits that make it differ from the bound.
  msg = testing::invalid_argument_message([] {
    settings_from_values<HbaoSettings>({{"radius", 1.0000000000000002e30}}, kHbaoFields, "hbao");
  });
  EXPECT_NE(msg.find("got 1.0000000000000002e+30"), std::string::npos) << msg;
  // Short values keep their short form.
  msg = testing::invalid_argument_message([] {
    settings_from_values<HbaoSettings>({{"directions", 0.5}}, kHbaoFields, "hbao");
  });
  EXPECT_NE(msg.find("got 0.5"), std::string::npos) << msg;
}

TEST(Settings, ExactNumberReadsBack) {
  EXPECT_EQ(detail::exact_number(2147483648.0), "2147483648");
  EXPECT_EQ(detail::exact_number(1e30), "1e+30");
  EXPECT_EQ(detail::exact_number(0.1f), "0.1");
  EXPECT_EQ(detail::exact_number(0.1), "0.1");
  EXPECT_EQ(detail::exact_number(16777217.0), "16777217");
  EXPECT_EQ(detail::exact_number(std::nextafter(1.0f, 2.0f)), "1.0000001");
  EXPECT_EQ(detail::exact_number(std::numeric_limits<double>::quiet_NaN()), "nan");
  EXPECT_EQ(detail::exact_number(-std::numeric_limits<double>::infinity()), "-inf");
}

}  // namespace
}  // namespace aolab
