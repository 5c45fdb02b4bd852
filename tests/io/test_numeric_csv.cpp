// User-given numeric CSV tables (probe trajectories, measured force curves): good files read
// back, bad ones fail with the file and line in the message.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "engine/error.hpp"
#include "io/numeric_csv.hpp"

namespace vb {
namespace {

std::string write_temp(const std::string& name, const std::string& text) {
  const std::string path = (std::filesystem::temp_directory_path() / ("vb_numeric_csv_" + name)).string();
  std::ofstream(path) << text;
  return path;
}

std::string error_of(const std::string& path) {
  try {
    read_numeric_csv(path, {"displacement_mm", "force_n"});
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(NumericCsv, ReadsRowsSkippingCommentsAndBlankLines) {
  const std::string path = write_temp("good.csv", "# measured\ndisplacement_mm, force_n\n\n0,0\n1.5,2e-3\r\n");
  const auto rows = read_numeric_csv(path, {"displacement_mm", "force_n"});
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_DOUBLE_EQ(rows[1][0], 1.5);
  EXPECT_DOUBLE_EQ(rows[1][1], 2e-3);
}

TEST(NumericCsv, BadFilesNameTheLine) {
  EXPECT_NE(error_of(write_temp("header.csv", "disp,force\n0,0\n")).find("header"), std::string::npos);
  const std::string text = error_of(write_temp("text.csv", "displacement_mm,force_n\n0,0\n1,abc\n"));
  EXPECT_NE(text.find(":3"), std::string::npos) << text;
  EXPECT_NE(text.find("abc"), std::string::npos) << text;
  EXPECT_NE(error_of(write_temp("fields.csv", "displacement_mm,force_n\n1,2,3\n")).find("3 fields"), std::string::npos);
  EXPECT_NE(error_of(write_temp("nan.csv", "displacement_mm,force_n\n1,nan\n")).find("finite"), std::string::npos);
  EXPECT_NE(error_of(write_temp("empty.csv", "")).find("empty"), std::string::npos);
  EXPECT_NE(error_of(write_temp("norows.csv", "displacement_mm,force_n\n")).find("no rows"), std::string::npos);
  EXPECT_NE(error_of("/nonexistent/curve.csv").find("cannot open"), std::string::npos);
}

}  // namespace
}  // namespace vb
