// The one Median, the one comma splitter and the one numeric Jacobian of calib/core.
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/json_file.h"
#include "calib/core/median.h"
#include "calib/core/numeric_jacobian.h"

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
