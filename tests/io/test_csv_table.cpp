#include <gtest/gtest.h>

#include "io/csv_table.hpp"

namespace vb {
namespace {

TEST(CsvTable, QuotesOnlyWhatNeedsIt) {
  EXPECT_EQ(csv_field("plain"), "plain");
  EXPECT_EQ(csv_field("a,b"), "\"a,b\"");
  EXPECT_EQ(csv_field("say \"hi\""), "\"say \"\"hi\"\"\"");
  EXPECT_EQ(csv_field("two\nlines"), "\"two\nlines\"");
  EXPECT_EQ(csv_line({"a", "", "b,c"}), "a,,\"b,c\"\n");
}

TEST(CsvTable, NumbersReadBackExactly) {
  for (double x : {0.1, 1.0 / 3.0, -2.5e-7, 3000.0, 1e300}) EXPECT_EQ(std::stod(shortest_number_text(x)), x);
  EXPECT_EQ(shortest_number_text(0.1), "0.1");
  EXPECT_EQ(shortest_number_text(3000.0), "3000");
  EXPECT_EQ(shortest_number_text(1.0 / 0.0), "");
}

}  // namespace
}  // namespace vb
