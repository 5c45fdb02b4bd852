#include "io/numeric_csv.hpp"

#include <charconv>
#include <cmath>
#include <fstream>

#include "engine/error.hpp"

namespace vb {
namespace {

std::string trimmed(const std::string& text) {
  const auto first = text.find_first_not_of(" \t\r");
  if (first == std::string::npos) return {};
  return text.substr(first, text.find_last_not_of(" \t\r") - first + 1);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> fields;
  std::size_t begin = 0;
  for (;;) {
    const auto comma = line.find(',', begin);
    fields.push_back(trimmed(line.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin)));
    if (comma == std::string::npos) return fields;
    begin = comma + 1;
  }
}

std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& n : names) text += (text.empty() ? "" : ",") + n;
  return text;
}

}  // namespace

std::vector<std::vector<double>> read_numeric_csv(const std::string& path, const std::vector<std::string>& columns) {
  std::ifstream in(path);
  require(bool(in), "cannot open '" + path + "'", path, "check the path");
  std::string line;
  int line_number = 0;
  bool header = false;
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    ++line_number;
    const std::string text = trimmed(line);
    if (text.empty() || text[0] == '#') continue;
    const std::string where = path + ":" + std::to_string(line_number);
    const std::vector<std::string> fields = split(text);
    if (!header) {
      require(fields == columns, "the header is '" + text + "', expected '" + joined(columns) + "'", where,
              "the first line names the columns, with their units");
      header = true;
      continue;
    }
    require(fields.size() == columns.size(),
            std::to_string(fields.size()) + " fields where the header has " + std::to_string(columns.size()), where);
    std::vector<double> row(fields.size());
    for (std::size_t k = 0; k < fields.size(); ++k) {
      const std::string& f = fields[k];
      const auto [end, ec] = std::from_chars(f.data(), f.data() + f.size(), row[k]);
      require(ec == std::errc() && end == f.data() + f.size() && !f.empty() && std::isfinite(row[k]),
              "'" + f + "' in column " + columns[k] + " is not a finite number", where);
    }
    rows.push_back(std::move(row));
  }
  require(header, "the file is empty: no header '" + joined(columns) + "'", path);
  require(!rows.empty(), "the file has a header but no rows", path);
  return rows;
}

}  // namespace vb
