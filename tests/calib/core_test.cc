// The one Median, the one comma splitter and the one numeric Jacobian of calib/core.
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/json_file.h"
#include "calib/core/median.h"
#include "calib/core/numeric_jacobian.h"
#include "calib/core/svg.h"

#include <gtest/gtest.h>

#include <cmath>

namespace aerocal {
namespace {

TEST(Median, OddEvenAndEmpty) {
  EXPECT_DOUBLE_EQ(Median({3.0, 1.0, 2.0}), 2.0);
  EXPECT_DOUBLE_EQ(Median({4.0, 1.0, 3.0, 2.0}), 2.5);  // mean of the two middle values
  EXPECT_DOUBLE_EQ(Median({0.5, 0.5}), 0.5);
  EXPECT_DOUBLE_EQ(Median({7.0}), 7.0);
  EXPECT_TRUE(std::isnan(Median({})));  // unknown, never 0
}

TEST(SplitCommaList, TrimsAndDropsOrKeepsEmptyFields) {
  using V = std::vector<std::string>;
  EXPECT_EQ(SplitCommaList(" c, K1 ,,K2,"), (V{"c", "K1", "K2"}));
  EXPECT_EQ(SplitCommaList("a, b,", {true, true}), (V{"a", "b", ""}));  // CSV rows
  EXPECT_EQ(SplitCommaList(" 1,\n2", {false, true}), (V{" 1", "\n2"}));
  EXPECT_EQ(SplitCommaList("A=x.tif,B=y.tif"), (V{"A=x.tif", "B=y.tif"}));
  EXPECT_TRUE(SplitCommaList("").empty());
  EXPECT_TRUE(SplitCommaList(",", {}).empty());
}

TEST(NumericJacobian, LinearAndQuadraticFunctions) {
  const auto f = [](const std::vector<double>& x) {
    return Eigen::Vector2d(2 * x[0] - 3 * x[1], x[0] * x[0]);
  };
  const Eigen::MatrixXd j = NumericJacobian(f, {1.5, -2.0});
  ASSERT_EQ(j.rows(), 2);
  ASSERT_EQ(j.cols(), 2);
  EXPECT_NEAR(j(0, 0), 2.0, 1e-9);
  EXPECT_NEAR(j(0, 1), -3.0, 1e-9);
  EXPECT_NEAR(j(1, 0), 3.0, 1e-8);
  EXPECT_NEAR(j(1, 1), 0.0, 1e-12);
}

}  // namespace
}  // namespace aerocal

namespace aerocal {
namespace {

// A number beyond the double range is no parse_error in nlohmann's parser (out_of_range, thrown
// from the parse): found by fuzz/camera_formats through the OpenSfM reader. It is bad input.
TEST(ParseJsonText, NumberOverflowIsAnInputErrorNamingTheFile) {
  try {
    ParseJsonText("{\"data\": [-2.9e999]}", "cameras.json");
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cameras.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("invalid JSON"), std::string::npos) << e.what();
  }
}

// Every JSON reader refuses a key given twice in one object (nlohmann would keep the last), at any
// depth, naming the enclosing keys; the same key in two objects is fine.
TEST(ParseJsonText, AKeyGivenTwiceInOneObjectIsAnInputErrorNamingItsPath) {
  EXPECT_NO_THROW(
      ParseJsonText(R"({"a": {"k": 1}, "b": {"k": 2}, "c": [{"k": 1}, {"k": 2}]})", "result.json"));
  const std::pair<const char*, const char*> cases[] = {
      {R"({"kind": "adjust", "kind": "flight"})", "result.json: key \"kind\" occurs twice"},
      {R"({"cameras": {"c1": {"c": 1, "x0": 2, "c": 3}}})",
       "result.json: cameras / c1: key \"c\" occurs twice"},
      {R"({"list": [{"u": 1}, {"u": 2, "u": 3}]})", "result.json: list: key \"u\" occurs twice"}};
  for (const auto& [text, message] : cases) {
    try {
      ParseJsonText(text, "result.json");
      ADD_FAILURE() << "accepted " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace aerocal

namespace aerocal {
namespace {

// Ticks are 1, 2 or 5 times a power of ten, at most `count` intervals, inside the range.
TEST(NiceTicks, OneTwoFiveStepsInsideTheRange) {
  EXPECT_EQ(NiceTicks(0.0, 3.7), (std::vector<double>{0, 1, 2, 3}));
  EXPECT_EQ(NiceTicks(0.0, 10.0), (std::vector<double>{0, 2, 4, 6, 8, 10}));
  const std::vector<double> small = NiceTicks(0.0012, 0.0089);
  ASSERT_EQ(small.size(), 4u);  // step 0.002: 0.002 .. 0.008
  EXPECT_NEAR(small.front(), 0.002, 1e-15);
  EXPECT_NEAR(small.back(), 0.008, 1e-15);
  const std::vector<double> negative = NiceTicks(-37.0, 12.0);  // step 10
  EXPECT_EQ(negative, (std::vector<double>{-30, -20, -10, 0, 10}));
  EXPECT_EQ(NiceTicks(5.0, 5.0), (std::vector<double>{5.0}));
}

TEST(SvgText, UserTextIsEscapedAndAxesAndScaleBarsAreLabelled) {
  EXPECT_EQ(SvgEscape("a<b>&\"c'"), "a&lt;b&gt;&amp;&quot;c&apos;");
  SvgPanel panel;
  panel.left = 50, panel.bottom = 300, panel.width = 200, panel.height = 100;
  panel.x_lo = 0, panel.x_hi = 4000, panel.y_lo = 0, panel.y_hi = 2.5;
  EXPECT_DOUBLE_EQ(panel.X(2000), 150);
  EXPECT_DOUBLE_EQ(panel.Y(2.5), 200);
  const std::string axes = SvgAxes(panel, "radius (px)", "<distortion> (px)");
  for (const char* text :
       {">0<", ">1000<", ">4000<", ">0.5<", ">2.5<", "radius (px)", "&lt;distortion&gt; (px)"})
    EXPECT_NE(axes.find(text), std::string::npos) << text;
  // 0.37 m per SVG pixel, at most 300 px: 111 m fit, so the bar is 100 m long (270.3 px).
  const std::string bar = SvgScaleBar(10, 20, 0.37, 300, "m");
  EXPECT_NE(bar.find(">100 m<"), std::string::npos) << bar;
  EXPECT_NE(bar.find("x2=\"280.3\""), std::string::npos) << bar;
}

}  // namespace
}  // namespace aerocal
