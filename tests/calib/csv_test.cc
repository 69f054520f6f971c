#include "calib/core/csv.h"

#include <gtest/gtest.h>

namespace aerocal {
namespace {

TEST(CsvTable, ReadsHeaderCommentsAndBlankLines) {
  const auto t =
      CsvTable::Parse("# comment\nframe,point,u\n\n0001, t1 ,12.5\n# x\n0002,t2,\n", "f.csv");
  ASSERT_EQ(t.rows().size(), 2u);
  EXPECT_EQ(t.rows()[0].line, 4);
  EXPECT_EQ(t.String(t.rows()[0], "point"), "t1");
  EXPECT_DOUBLE_EQ(t.Number(t.rows()[0], "u"), 12.5);
  EXPECT_FALSE(t.OptionalNumber(t.rows()[1], "u").has_value());
}

TEST(CsvTable, BadNumberNamesFileLineAndValue) {
  const auto t = CsvTable::Parse("a,b\n1,2\n3,x7\n", "obs.csv");
  try {
    t.Number(t.rows()[1], "b");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "obs.csv:3: column 'b' must be a number (got 'x7')");
  }
}

TEST(CsvTable, TooManyFieldsAndMissingColumnsAreErrors) {
  EXPECT_THROW(CsvTable::Parse("a,b\n1,2,3\n", "f.csv"), InputError);
  const auto t = CsvTable::Parse("a,b\n1,2\n", "f.csv");
  try {
    t.RequireColumns({"a", "sigma_px", "c"});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "f.csv:1: missing column 'sigma_px'");
  }
  EXPECT_THROW(CsvTable::Parse("# only a comment\n", "e.csv"), InputError);
}

}  // namespace
}  // namespace aerocal
