#pragma once
/// Small numeric CSV tables that users give (probe trajectories, measured force curves): a header
/// naming the columns (units in the names), then rows of finite numbers.
#include <string>
#include <vector>

namespace vb {

/// Reads `path`, whose header must be exactly `columns` (spaces around names ignored); lines
/// that are empty or start with '#' are skipped. Throws vb::Error naming the file and line for a
/// missing file, a wrong header, a wrong field count, a field that is not a finite number, or no
/// rows. Returns the rows (each columns.size() numbers).
std::vector<std::vector<double>> read_numeric_csv(const std::string& path, const std::vector<std::string>& columns);

}  // namespace vb
