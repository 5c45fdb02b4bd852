// metrics.csv: one header and one row with the same number of fields, units in the names, empty
// cells for metrics that do not apply, one group of columns per torus.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "io/metrics_csv.hpp"

namespace vb {
namespace {

std::string cell(const std::vector<std::pair<std::string, std::string>>& row, const std::string& name) {
  for (const auto& [column, value] : row)
    if (column == name) return value;
  ADD_FAILURE() << "no column " << name;
  return {};
}

TEST(MetricsCsv, OneRowWithTumourAndToriColumns) {
  RunSummary s;
  s.converged = true;
  s.stop_reason = "equilibrium";
  s.max_displacement_m = 0.0125;
  TorusResult t;
  t.name = "upper";
  t.minor_radius_m = 0.012;
  t.force_n = Vec3(0, 3, 4);
  t.contact_area_m2 = 2e-4;
  t.contact_elements = 12;
  t.max_penetration_run_m = 1e-7;
  s.tori = {t};
  PositioningMetrics m;
  TumourMetrics tumour;
  tumour.tissue = "tumour";
  tumour.rest_centroid_m = Vec3(0.01, 0.02, 0.03);
  tumour.final_centroid_m = Vec3(0.01, 0.024, 0.03);
  m.tumour = tumour;

  const auto row = metrics_row(s, m);
  EXPECT_EQ(cell(row, "converged"), "1");
  EXPECT_EQ(cell(row, "max_displacement_mm"), "12.5");
  EXPECT_EQ(cell(row, "tumour_dy_mm"), "4");
  EXPECT_EQ(cell(row, "tumour_displacement_mm"), "4");
  EXPECT_EQ(cell(row, "tumour_target_distance_mm"), "");       // no target
  EXPECT_EQ(cell(row, "tumour_chest_wall_distance_mm"), "");   // no chest wall
  EXPECT_EQ(cell(row, "upper_force_n"), "5");
  EXPECT_EQ(cell(row, "upper_minor_radius_mm"), "12");
  EXPECT_EQ(cell(row, "upper_contact_area_mm2"), "200");
  EXPECT_EQ(cell(row, "upper_contact_elements"), "12");
  EXPECT_EQ(cell(row, "device_force_n"), "5");

  const std::string path = (std::filesystem::temp_directory_path() / "vb_metrics_test.csv").string();
  write_metrics_csv(path, s, m);
  std::ifstream in(path);
  std::string header, values, extra;
  ASSERT_TRUE(std::getline(in, header));
  ASSERT_TRUE(std::getline(in, values));
  EXPECT_FALSE(std::getline(in, extra)) << "one row only";
  const auto fields = [](const std::string& line) { return std::count(line.begin(), line.end(), ',') + 1; };
  EXPECT_EQ(fields(header), std::ptrdiff_t(row.size()));
  EXPECT_EQ(fields(values), std::ptrdiff_t(row.size()));
  EXPECT_EQ(header.rfind("converged,stop_reason,", 0), 0u) << header;
  std::filesystem::remove(path);
}

TEST(MetricsCsv, SameColumnsWithoutDevice) {
  // A scene without tori still writes every positioning column (a sweep can concatenate rows).
  const auto row = metrics_row(RunSummary{}, PositioningMetrics{});
  EXPECT_EQ(cell(row, "tumour_rest_x_mm"), "");
  EXPECT_EQ(cell(row, "breast_chest_wall_mean_distance_mm"), "");
  for (const auto& [column, value] : row) EXPECT_EQ(column.find("device_"), std::string::npos) << column;
}

}  // namespace
}  // namespace vb
