#include "io/scene_overrides.hpp"
#include "io/toml_text.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <sstream>
#include <string_view>

#include "engine/error.hpp"
#include "io/did_you_mean.hpp"

namespace vb {
namespace {

bool is_bare_key(std::string_view part) {
  return !part.empty() && std::all_of(part.begin(), part.end(), [](unsigned char c) {
    return std::isalnum(c) || c == '_' || c == '-';
  });
}

bool is_index(std::string_view part) {
  return !part.empty() && std::all_of(part.begin(), part.end(), [](unsigned char c) { return std::isdigit(c); });
}

std::string key_text(const std::string& part) { return is_bare_key(part) ? part : toml_string_text(part); }

/// "a.b.c" for the first n parts (quoted where TOML needs it).
std::string dotted(const std::vector<std::string>& parts, std::size_t n) {
  std::string s;
  for (std::size_t i = 0; i < n; ++i) s.append(i ? "." : "").append(key_text(parts[i]));
  return s;
}

std::string describe(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::table: return "a table";
    case toml::node_type::array: return "an array";
    case toml::node_type::string: return "a string";
    case toml::node_type::boolean: return "a boolean";
    default: return node.is_number() ? "a number" : "a date/time";
  }
}

bool has_non_finite(const toml::node& node) {
  if (const auto* f = node.as_floating_point()) return !std::isfinite(f->get());
  if (const auto* a = node.as_array())
    return std::any_of(a->begin(), a->end(), [](const toml::node& n) { return has_non_finite(n); });
  return false;
}

/// The value of `text` as a TOML value in a one-key table ("v"), or nothing when it is not one.
std::optional<toml::table> parse_value(const std::string& text) {
  try {
    toml::table t = toml::parse("v = " + text + "\n");
    if (t.size() == 1 && t.contains("v")) return t;
  } catch (const toml::parse_error&) {
  }
  return std::nullopt;
}

/// Byte offsets of the starts of lines (1-based line L starts at starts[L - 1]); toml++ counts
/// columns in code points, so a column becomes an offset by walking UTF-8 sequences.
class TextPositions {
 public:
  explicit TextPositions(const std::string& text) : text_(text) {
    starts_.push_back(0);
    for (std::size_t i = 0; i < text.size(); ++i)
      if (text[i] == '\n') starts_.push_back(i + 1);
  }
  std::size_t offset(const toml::source_position& p) const {
    std::size_t at = starts_.at(p.line - 1);
    for (std::size_t c = 1; c < p.column && at < text_.size(); ++c) {
      const unsigned char lead = static_cast<unsigned char>(text_[at]);
      at += lead < 0x80 ? 1 : lead < 0xE0 ? 2 : lead < 0xF0 ? 3 : 4;
    }
    return at;
  }
  /// Offset just after line `line` (the start of the next line).
  std::size_t after_line(std::size_t line) const { return line < starts_.size() ? starts_[line] : text_.size(); }
  std::string line_text(std::size_t line) const {
    const std::size_t begin = starts_.at(line - 1);
    return text_.substr(begin, after_line(line) - begin);
  }

 private:
  const std::string& text_;
  std::vector<std::size_t> starts_;
};

/// Path walked through a parsed tree: the nodes found and whether each part was an array index.
struct Walk {
  std::vector<toml::node*> nodes;  ///< nodes[i]: the node at parts[0..i]
  std::vector<bool> index;         ///< parts[i] addressed an array element
  std::size_t found() const { return nodes.size(); }
};

[[noreturn]] void fail_key(const std::string& source, const std::string& key, const std::string& what,
                           const std::string& hint = {}) {
  throw Error(what, source + " key '" + key + "'", hint);
}

Walk walk(toml::table& root, const std::vector<std::string>& parts, const std::string& source) {
  Walk w;
  toml::node* node = &root;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (toml::table* t = node->as_table()) {
      node = t->get(parts[i]);
      if (!node) return w;
      w.index.push_back(false);
    } else if (toml::array* a = node->as_array()) {
      const std::string here = dotted(parts, i);
      if (!is_index(parts[i]) || std::stoull(parts[i].substr(0, 18)) == 0)
        fail_key(source, dotted(parts, parts.size()), "'" + here + "' is an array; its elements are numbered from 1",
                 "e.g. " + here + ".1");
      const std::size_t n = std::stoull(parts[i].substr(0, 18));
      if (n > a->size())
        fail_key(source, dotted(parts, parts.size()),
                 "'" + here + "' has " + std::to_string(a->size()) + " element" + (a->size() == 1 ? "" : "s") +
                     ", there is no element " + parts[i],
                 "elements are numbered 1 to " + std::to_string(a->size()));
      node = a->get(n - 1);
      w.index.push_back(true);
    } else {
      fail_key(source, dotted(parts, parts.size()),
               std::string("'").append(dotted(parts, i)) + "' is " + describe(*node) + ", it has no key '" + parts[i] + "'");
    }
    w.nodes.push_back(node);
  }
  return w;
}

/// Sets `value` at `parts` in `root`, creating missing tables (the in-memory twin of the text edit).
void set_in_tree(toml::table& root, const std::vector<std::string>& parts, const toml::node& value) {
  toml::node* node = &root;
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    if (toml::array* a = node->as_array()) {
      node = a->get(std::stoull(parts[i]) - 1);
    } else {
      toml::table& t = *node->as_table();
      if (!t.contains(parts[i])) t.insert(parts[i], toml::table{});
      node = t.get(parts[i]);
    }
  }
  value.visit([&](const auto& v) {
    if (toml::array* a = node->as_array()) {
      a->replace(a->cbegin() + static_cast<long>(std::stoull(parts.back()) - 1), v);
    } else {
      node->as_table()->insert_or_assign(parts.back(), v);
    }
  });
}

/// true when the line holds the header of the table at parts[0..n): [a.b] or, for an element of
/// an array of tables, [[a.b]].
bool is_header_of(std::string line, const std::vector<std::string>& parts, std::size_t n, bool array_element) {
  if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
  line.erase(std::remove_if(line.begin(), line.end(), [](unsigned char c) { return std::isspace(c); }), line.end());
  const std::string path = dotted(parts, array_element ? n - 1 : n);
  return line == (array_element ? "[[" + path + "]]" : "[" + path + "]");
}

/// Keys of a table, for hints.
std::vector<std::string_view> keys_of(const toml::table& t) {
  std::vector<std::string_view> keys;
  for (const auto& entry : t) keys.push_back(entry.first.str());
  return keys;
}

std::string joined(const std::vector<std::string_view>& words) {
  std::string s;
  for (std::string_view w : words) s += (s.empty() ? "" : ", ") + std::string(w);
  return s;
}

}  // namespace

std::vector<std::string> split_scene_key(const std::string& key) {
  std::vector<std::string> parts(1);
  std::vector<bool> quoted_part(1, false);
  bool in_quotes = false;
  for (char c : key) {
    if (c == '"') {
      in_quotes = !in_quotes;
      quoted_part.back() = true;
    } else if (c == '.' && !in_quotes) {
      parts.emplace_back();
      quoted_part.push_back(false);
    } else {
      parts.back() += c;
    }
  }
  if (in_quotes) throw Error("unclosed quote in key '" + key + "'", "", "write e.g. materials.\"my tissue\".E");
  for (std::size_t i = 0; i < parts.size(); ++i)
    if (parts[i].empty() && !quoted_part[i])
      throw Error("key '" + key + "' has an empty part", "", "keys are dotted paths such as materials.adipose.E");
  return parts;
}

SceneOverride parse_scene_setting(const std::string& argument) {
  const std::string where = "--set " + argument;
  const std::string example = "e.g. --set materials.adipose.E=3000 or --set gravity.posture=supine";
  const std::size_t eq = argument.find('=');
  if (eq == std::string::npos) throw Error("expected KEY=VALUE", where, example);
  SceneOverride setting;
  setting.key = argument.substr(0, eq);
  const auto space = [](unsigned char c) { return std::isspace(c) != 0; };
  setting.key.erase(setting.key.begin(), std::find_if_not(setting.key.begin(), setting.key.end(), space));
  while (!setting.key.empty() && space(setting.key.back())) setting.key.pop_back();
  if (!setting.key.empty() && setting.key[0] == '+') {
    setting.key.erase(0, 1);
    setting.add = true;
  }
  if (setting.key.empty()) throw Error("the key is empty", where, example);
  try {
    (void)split_scene_key(setting.key);
    setting.value = toml_value_text(argument.substr(eq + 1));
  } catch (const Error& e) {
    throw Error(e.problem(), where, e.hint());
  }
  return setting;
}

std::string toml_string_text(const std::string& value) {
  std::ostringstream out;
  out << toml::value<std::string>(value);
  return out.str();
}

std::string toml_value_text(const std::string& word_in) {
  std::string word = word_in;
  const auto space = [](unsigned char c) { return std::isspace(c) != 0; };
  while (!word.empty() && space(word.back())) word.pop_back();
  word.erase(word.begin(), std::find_if_not(word.begin(), word.end(), space));
  if (word.empty()) throw Error("empty value", "", "give a number, a word, true/false or [a, b, c]");
  const std::optional<toml::table> parsed = parse_value(word);
  if (!parsed) return toml_string_text(word);
  const toml::node& node = *parsed->get("v");
  if (node.is_table()) throw Error("value '" + word + "' is a table", "", "vary the keys inside it one by one");
  if (has_non_finite(node)) throw Error("value '" + word + "' is not a finite number", "", "scene values must be finite");
  return word;
}

std::string apply_scene_overrides(const std::string& text_in, const std::string& source,
                                  const std::vector<SceneOverride>& overrides) {
  std::string text = text_in;
  if (!text.empty() && text.back() != '\n') text += '\n';
  toml::table root = parse_toml_text(text, source);
  toml::table expected = root;  // the overrides applied to the tree: what the edited text must parse to
  const TextPositions positions(text);

  struct Replacement {
    std::size_t begin, end;
    std::string text;
  };
  std::vector<Replacement> replacements;
  std::map<std::size_t, std::string> insertions;                   // offset → lines inserted there
  std::vector<std::pair<std::string, std::string>> appended;        // new [table] → its lines
  std::vector<std::vector<std::string>> seen;

  for (const SceneOverride& o : overrides) {
    const std::vector<std::string> parts = split_scene_key(o.key);
    const std::string key = dotted(parts, parts.size());
    for (const auto& other : seen) {
      const std::size_t n = std::min(other.size(), parts.size());
      if (std::equal(parts.begin(), parts.begin() + static_cast<long>(n), other.begin()))
        fail_key(source, key, "overlaps the override of '" + dotted(other, other.size()) + "'",
                 "set each value once");
    }
    seen.push_back(parts);
    const std::optional<toml::table> value = parse_value(o.value);
    if (!value) fail_key(source, key, "'" + o.value + "' is not a TOML value", "quote strings: \"prone\"");
    const std::string value_text = o.value;

    const Walk w = walk(root, parts, source);
    if (w.found() == parts.size()) {
      const toml::node& node = *w.nodes.back();
      if (const toml::table* t = node.as_table())
        fail_key(source, key, "'" + key + "' is a table, not a value", "give one of its keys: " + joined(keys_of(*t)));
      if (const toml::array* a = node.as_array(); a && a->is_array_of_tables())
        fail_key(source, key, "'" + key + "' is an array of tables, not a value", "give an entry's key, e.g. " + key + ".1.…");
      replacements.push_back({positions.offset(node.source().begin), positions.offset(node.source().end), value_text});
    } else {
      const std::size_t found = w.found();
      const toml::table& deepest = found ? *w.nodes.back()->as_table() : root;
      const std::string missing = dotted(parts, found + 1);
      if (!o.add) {
        std::string hint = did_you_mean(parts[found], keys_of(deepest));
        if (hint.empty())
          hint = "the scene has no '" + missing + "'; to add it, write '+" + key + "' (docs/SWEEP.md)";
        fail_key(source, key, "no such key in the scene: '" + missing + "'", hint);
      }
      if (parts.size() == 1) fail_key(source, key, "a scene has no top-level values", "keys live in tables, e.g. solver.dt");
      const std::string line = key_text(parts.back()) + " = " + value_text + "\n";
      const bool parent_exists = found == parts.size() - 1;
      const bool parent_is_element = parent_exists && found > 0 && w.index[found - 1];
      std::size_t header_line = 0;
      if (parent_exists && found > 0) header_line = w.nodes.back()->source().begin.line;
      if (header_line && is_header_of(positions.line_text(header_line), parts, found, parent_is_element)) {
        insertions[positions.after_line(header_line)] += line;
      } else {
        if (std::find(w.index.begin(), w.index.end(), true) != w.index.end())
          fail_key(source, key, "cannot add a table inside an array entry", "add it to the scene file, then vary it");
        const std::string table = dotted(parts, parts.size() - 1);
        const auto it = std::find_if(appended.begin(), appended.end(), [&](const auto& a) { return a.first == table; });
        if (it == appended.end()) appended.emplace_back(table, line);
        else it->second += line;
      }
    }
    set_in_tree(expected, parts, *value->get("v"));
  }

  // Apply from the end so earlier offsets stay valid.
  std::sort(replacements.begin(), replacements.end(), [](const auto& a, const auto& b) { return a.begin > b.begin; });
  std::string out = text;
  for (auto it = insertions.rbegin(); it != insertions.rend(); ++it) {
    while (!replacements.empty() && replacements.front().begin >= it->first) {
      out.replace(replacements.front().begin, replacements.front().end - replacements.front().begin,
                  replacements.front().text);
      replacements.erase(replacements.begin());
    }
    out.insert(it->first, it->second);
  }
  for (const Replacement& r : replacements) out.replace(r.begin, r.end - r.begin, r.text);
  for (const auto& [table, lines] : appended) out += "\n[" + table + "]\n" + lines;

  // The edit must give exactly the tree the overrides describe.
  bool same = false;
  std::string why;
  try {
    same = parse_toml_text(out, source) == expected;
  } catch (const Error& e) {
    why = ": " + e.problem();
  }
  if (!same) {
    std::string keys;
    for (const SceneOverride& o : overrides) keys.append(keys.empty() ? "" : ", ").append(o.add ? "+" : "").append(o.key);
    throw Error("the scene text could not be edited to set " + keys + why, source,
                "set these values in the scene file itself (e.g. add the key there, then vary it without '+')");
  }
  return out;
}

std::string toml_value_plain(const std::string& value_text) {
  const std::optional<toml::table> parsed = parse_value(value_text);
  if (parsed && parsed->get("v")->is_string()) return parsed->get("v")->as_string()->get();
  return value_text;
}

std::string scene_string_value(const std::string& text, const std::string& source, const std::string& key) {
  toml::table root = parse_toml_text(text, source);
  const std::vector<std::string> parts = split_scene_key(key);
  const Walk w = walk(root, parts, source);
  if (w.found() != parts.size() || !w.nodes.back()->is_string()) return {};
  return w.nodes.back()->as_string()->get();
}

}  // namespace vb
