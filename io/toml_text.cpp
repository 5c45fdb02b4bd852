#include "io/toml_text.hpp"

#include <string_view>

#include "engine/error.hpp"

namespace vb {

toml::table parse_toml_text(const std::string& text, const std::string& source) {
  try {
    return toml::parse(std::string_view(text), std::string_view(source));
  } catch (const toml::parse_error& e) {
    const toml::source_position& at = e.source().begin;
    throw Error("TOML syntax error: " + std::string(e.description()),
                source + ":" + std::to_string(at.line) + ":" + std::to_string(at.column),
                "fix the TOML syntax; see https://toml.io");
  }
}

}  // namespace vb
