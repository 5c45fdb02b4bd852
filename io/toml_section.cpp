#include "io/toml_section.hpp"

#include <sstream>

namespace vb::scene_toml {

bool contains(const Keys& words, std::string_view word) {
  return std::find(words.begin(), words.end(), word) != words.end();
}

std::string joined(const Keys& words) {
  std::string s;
  for (std::string_view w : words) s += (s.empty() ? "" : ", ") + std::string(w);
  return s;
}

std::string choice_hint(std::string_view word, const Keys& accepted) {
  const std::string guess = did_you_mean(word, accepted);
  return (guess.empty() ? "" : guess + " ") + "accepted: " + joined(accepted);
}

std::string format_number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

std::string where_string(const std::string& source, int line, const std::string& key_path) {
  return source + (line > 0 ? ":" + std::to_string(line) : "") + " key '" + key_path + "'";
}

int line_of(const toml::source_region& region) { return static_cast<int>(region.begin.line); }

std::string describe(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a float";
    case toml::node_type::boolean:
      return "a boolean";
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "an array of " + std::to_string(node.as_array()->size()) + " items";
    default:
      return "a date/time";
  }
}

std::optional<double> as_double(const toml::node& node) {
  if (const auto* i = node.as_integer()) return static_cast<double>(i->get());
  if (const auto* f = node.as_floating_point()) return f->get();
  return std::nullopt;
}

const toml::table& empty_table() {
  static const toml::table table;
  return table;
}

}  // namespace vb::scene_toml
