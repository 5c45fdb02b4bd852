#pragma once
/// CSV text (RFC 4180) for tables that scripts read: metrics.csv, timing.csv.
#include <string>
#include <vector>

namespace vb {

/// A field as CSV: quoted (quotes doubled) when it holds a comma, a quote or a line break.
std::string csv_field(const std::string& text);

/// One CSV record, fields joined by commas, ending in "\n".
std::string csv_line(const std::vector<std::string>& fields);

/// The shortest text that reads back as exactly `x` (e.g. 0.1, 3000, 1e-05); "" for NaN/inf.
std::string shortest_number_text(double x);

}  // namespace vb
