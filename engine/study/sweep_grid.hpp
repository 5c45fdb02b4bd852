#pragma once
/// The grid of a parameter sweep: each --vary gives a key and its values; the cases are their
/// Cartesian product, the first parameter varying slowest (docs/SWEEP.md, "Grid").
#include <cstddef>
#include <string>
#include <vector>

#include "io/scene_overrides.hpp"

namespace vb {

struct SweepParameter {
  std::string key;                  ///< dotted scene key as given (without the leading '+')
  bool add = false;                 ///< '+KEY': the scene may lack the key (SceneOverride::add)
  std::vector<std::string> values;  ///< TOML value texts, in sweep order
};

/// Parses one --vary argument:
///   KEY=FROM:TO:N       N evenly spaced values from FROM to TO (integers when FROM and TO are
///                       integers and the step is whole; floats rounded to 12 significant digits)
///   KEY=FROM:TO:N:log   N values evenly spaced in log(value) (FROM, TO > 0)
///   KEY=a,b,c           a list: numbers, true/false, words (prone → "prone"), arrays [x, y, z]
///   +KEY=...            the same, adding KEY when the scene lacks it
/// Throws vb::Error naming the argument when it is malformed.
SweepParameter parse_vary(const std::string& argument);

class SweepGrid {
 public:
  /// Throws vb::Error when a key is given twice or the grid exceeds max_cases.
  explicit SweepGrid(std::vector<SweepParameter> parameters, std::size_t max_cases = 1000000);

  /// Number of cases: the product of the value counts (1 when there are no parameters).
  std::size_t size() const { return size_; }
  const std::vector<SweepParameter>& parameters() const { return parameters_; }

  /// The value text of each parameter in case `index` (0-based, < size()).
  std::vector<std::string> values_of(std::size_t index) const;
  /// The scene overrides of case `index`.
  std::vector<SceneOverride> overrides_of(std::size_t index) const;

 private:
  std::vector<SweepParameter> parameters_;
  std::size_t size_ = 1;
};

}  // namespace vb
