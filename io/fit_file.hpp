#pragma once
/// The [fit] table of a scene file → vb::FitSpec (docs/FIT.md). Strict like the scene parser:
/// unknown keys and bad values are vb::Error naming the file, line and dotted key. Relative
/// paths are relative to the scene file's folder.
#include <string>

#include "engine/fit/fit_spec.hpp"

namespace vb {

/// Throws vb::Error when the text has no [fit] table or the table is invalid.
FitSpec parse_fit_section(const std::string& scene_text, const std::string& scene_path);

}  // namespace vb
