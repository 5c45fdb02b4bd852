#pragma once
/// TOML text → table, with syntax errors as vb::Error naming file:line:column (scene files and
/// the sweep's overrides share it).
#include <toml++/toml.h>

#include <string>

namespace vb {

toml::table parse_toml_text(const std::string& text, const std::string& source);

}  // namespace vb
