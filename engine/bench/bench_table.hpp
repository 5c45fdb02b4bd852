#pragma once
/// Bench rows as JSON and CSV: SI inside, mm for lengths at the file boundary (docs/BENCHMARKS.md
/// lists the columns).
#include <nlohmann/json.hpp>
#include <string>

#include "engine/bench/trade_study.hpp"

namespace vb::bench {

/// One row; a value that does not apply (NaN) is null.
nlohmann::json row_json(const CaseResult& r);
/// The CSV header line (with newline) and one row (with newline); a value that does not apply is empty.
std::string csv_header();
std::string csv_row(const CaseResult& r);

}  // namespace vb::bench
