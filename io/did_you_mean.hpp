#pragma once
/// "did you mean ...?" hints for misspelt keys and names.
#include <string>
#include <string_view>
#include <vector>

namespace vb {

/// Levenshtein distance (insertions, deletions, substitutions).
std::size_t edit_distance(std::string_view a, std::string_view b);

/// "did you mean 'x'?" for the closest candidate within edit distance 2, else empty.
std::string did_you_mean(std::string_view word, const std::vector<std::string_view>& candidates);

}  // namespace vb
