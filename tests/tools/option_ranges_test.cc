// The validators every numeric option carries (tools/option_ranges.h, SeedCheck in
// tools/command_registry.h), in process on every kind of value. The CLI test that walks every
// option of every command (bad_input2_test.cc, OptionRanges) then needs only to show that each
// option is wired to its validator with the range it states.
#include "tools/option_ranges.h"

#include "tools/command_registry.h"

#include <CLI/CLI.hpp>
#include <gtest/gtest.h>

#include <string>

namespace aerocal::tools {
namespace {

// The validator's verdict on `text`: "" when accepted, else its message.
std::string Check(const CLI::Validator& validator, std::string text) { return validator(text); }

TEST(FiniteRange, RefusesNanInfinitiesTextAndValuesOutsideAClosedRange) {
  const CLI::Validator v = FiniteRange(-2, 5);
  for (const char* bad : {"nan",
                          "NaN",
                          "inf",
                          "-inf",
                          "infinity",
                          "1e308",
                          "-1e308",
                          "5.0001",
                          "-2.0001",
                          "",
                          "x",
                          "1x",
                          "1 "})
    EXPECT_NE(Check(v, bad), "") << "'" << bad << "'";
  for (const char* good : {"-2", "5", "0", "1e-300", "4.99999", "+3"})
    EXPECT_EQ(Check(v, good), "") << good;
  EXPECT_EQ(Check(v, "6"), "must be in [-2, 5] (got 6)");
  EXPECT_EQ(Check(v, "nan"), "must be a finite number in [-2, 5] (got 'nan')");
  EXPECT_EQ(Check(v, "x"), "must be a number in [-2, 5] (got 'x')");
  EXPECT_EQ(v.get_description(), "in [-2, 5]");
}

TEST(FiniteRange, AnOpenLowerEndRefusesTheEndItself) {
  const CLI::Validator v = PositiveUpTo(1e9);
  EXPECT_NE(Check(v, "0"), "");
  EXPECT_NE(Check(v, "-0"), "");
  EXPECT_NE(Check(v, "-1"), "");
  EXPECT_EQ(Check(v, "4.9e-324"), "");  // the smallest positive double is > 0
  EXPECT_EQ(Check(v, "1e9"), "");
  EXPECT_NE(Check(v, "1.0000001e9"), "");
  EXPECT_EQ(v.get_description(), "in (0, 1000000000]");
}

TEST(SeedCheck, DigitsWithinSixtyFourBitsOnly) {
  const CLI::Validator v = SeedCheck();
  for (const char* good : {"0", "7", "18446744073709551615"}) EXPECT_EQ(Check(v, good), "") << good;
  for (const char* bad : {"18446744073709551616", "-1", "nan", "inf", "1e3", "", "+1", "1.0"})
    EXPECT_NE(Check(v, bad), "") << "'" << bad << "'";
}

}  // namespace
}  // namespace aerocal::tools
