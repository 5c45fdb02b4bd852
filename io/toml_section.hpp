#pragma once
/// Typed, located access to the tables of a TOML file (scene files, their [fit] table): every
/// getter checks the value's type and range and throws a vb::Error naming file, line and dotted
/// key, with a hint; an absent key reads as std::nullopt, so defaults stay with the caller.
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "engine/error.hpp"
#include "engine/scene/scene.hpp"
#include "io/did_you_mean.hpp"

namespace vb::scene_toml {

using Keys = std::vector<std::string_view>;

/// A key reserved for a later version: rejected with "not supported yet" rather than "unknown",
/// so users of the documented design learn it exists.
struct LaterKey {
  std::string_view key;
  std::string_view hint;
};

/// A name accepted for a string-valued key, the value it maps to, and (for `kind` keys) the keys
/// a table of that kind may hold.
template <class E>
struct Named {
  std::string_view name;
  E value;
  Keys keys;  ///< empty for plain choices
};

template <class E>
using NameTable = std::vector<Named<E>>;

/// Whether `word` is one of `words`.
bool contains(const Keys& words, std::string_view word);
/// "a, b, c"
std::string joined(const Keys& words);
/// Hint for a value outside a fixed set: a close match if there is one, and the whole set.
std::string choice_hint(std::string_view word, const Keys& accepted);
/// A number for a message, as a stream prints it (6 significant digits: 0.001, 1e+30).
std::string format_number(double v);
/// "scene.toml:12 key 'materials.adipose.E'" (the line left out when unknown).
std::string where_string(const std::string& source, int line, const std::string& key_path);
int line_of(const toml::source_region& region);
/// "a string", "an array of 3 items", ...: what the file holds, for "expected X, got Y".
std::string describe(const toml::node& node);
/// An integer or float node's value; nullopt for other types.
std::optional<double> as_double(const toml::node& node);
/// A table with no keys: what an absent table reads as.
const toml::table& empty_table();

// ---- typed, located access to one TOML table -------------------------------------------------

/// One table of the scene with its dotted path: typed getters that throw located vb::Errors.
/// Getters return std::nullopt for an absent key, so defaults stay in the Scene structs.
class Section {
 public:
  Section(const toml::table& table, std::string path, const std::string& source)
      : table_(&table), path_(std::move(path)), source_(&source) {}

  int line() const { return line_of(table_->source()); }

  std::string key_path(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
  }

  /// The key's line, else (absent key) the table's.
  int line_of_key(std::string_view key) const {
    const auto it = table_->find(key);
    if (it == table_->end()) return line();
    if (const int l = line_of(it->second.source())) return l;
    return line_of(it->first.source());
  }

  std::string where(std::string_view key) const {
    return where_string(*source_, line_of_key(key), key_path(key));
  }

  [[noreturn]] void fail(std::string_view key, const std::string& what,
                         const std::string& hint = {}) const {
    throw Error(what, where(key), hint);
  }

  const toml::node* find(std::string_view key) const { return table_->get(key); }

  /// Every key must be in `allowed`; `later` keys get "not supported yet"; `context` follows
  /// "unknown key" in the message (e.g. " for kind 'box'").
  void check_keys(const Keys& allowed, const std::vector<LaterKey>& later = {},
                  std::string_view context = {}) const {
    const std::optional<std::string_view> key = first_key_not_in(allowed);
    if (!key) return;
    for (const LaterKey& l : later) {
      if (l.key == *key) fail(*key, key_path(*key) + " is not supported yet", std::string(l.hint));
    }
    std::string hint = did_you_mean(*key, allowed);
    if (hint.empty()) hint = "allowed keys here: " + joined(allowed);
    fail(*key, "unknown key" + std::string(context), hint);
  }

  std::optional<Section> table(std::string_view key) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    if (!node->is_table()) wrong_type(key, *node, "a table");
    return Section(*node->as_table(), key_path(key), *source_);
  }

  /// An absent table reads as an empty one, so every key takes its default.
  Section table_or_empty(std::string_view key) const {
    return table(key).value_or(Section(empty_table(), key_path(key), *source_));
  }

  /// `[[key]]` array of tables, each named "path.key[i]"; absent → none.
  std::vector<Section> tables(std::string_view key) const {
    const toml::node* node = find(key);
    if (!node) return {};
    const toml::array* array = node->as_array();
    const auto is_table = [](const toml::node& n) { return n.is_table(); };
    if (!array || !std::all_of(array->begin(), array->end(), is_table)) {
      wrong_type(key, *node, "an array of tables [[" + key_path(key) + "]]");
    }
    std::vector<Section> sections;
    for (std::size_t i = 0; i < array->size(); ++i) {
      sections.emplace_back(*array->get(i)->as_table(),
                            key_path(key) + "[" + std::to_string(i) + "]", *source_);
    }
    return sections;
  }

  /// Named sub-tables `[path.NAME]`, in file order.
  std::vector<std::pair<std::string, Section>> named_tables() const {
    std::vector<std::pair<std::string, Section>> sections;
    for (const auto& [key, node] : *table_) {
      if (!node.is_table()) wrong_type(key.str(), node, "a table [" + path_ + ".NAME]");
      sections.emplace_back(std::string(key.str()),
                            Section(*node.as_table(), key_path(key.str()), *source_));
    }
    std::stable_sort(sections.begin(), sections.end(), [](const auto& a, const auto& b) {
      return a.second.line() < b.second.line();
    });
    return sections;
  }

  std::optional<std::string> text(std::string_view key) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    if (!node->is_string()) wrong_type(key, *node, "a string");
    return node->as_string()->get();
  }

  /// An array of 1 to 3 finite numbers (Ogden parameters); absent → nullopt.
  std::optional<std::vector<double>> numbers(std::string_view key) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    const toml::array* array = node->as_array();
    if (!array || array->empty() || array->size() > 3) wrong_type(key, *node, "an array of 1 to 3 numbers");
    std::vector<double> out;
    for (const toml::node& n : *array) {
      const std::optional<double> x = as_double(n);
      if (!x || !std::isfinite(*x)) fail(key, "expected finite numbers, got " + describe(n));
      out.push_back(*x);
    }
    return out;
  }

  std::optional<bool> boolean(std::string_view key) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    if (!node->is_boolean()) wrong_type(key, *node, "true or false");
    return node->as_boolean()->get();
  }

  /// An array of strings; absent → nullopt.
  std::optional<std::vector<std::string>> strings(std::string_view key) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    const toml::array* array = node->as_array();
    const auto is_string = [](const toml::node& n) { return n.is_string(); };
    if (!array || !std::all_of(array->begin(), array->end(), is_string)) {
      wrong_type(key, *node, "an array of strings");
    }
    std::vector<std::string> out;
    for (const toml::node& n : *array) out.push_back(n.as_string()->get());
    return out;
  }

  /// Keys of this table with their sections-free values, in file order (for key → value maps).
  std::vector<std::string> keys() const {
    std::vector<std::pair<int, std::string>> found;
    for (const auto& entry : *table_) found.emplace_back(line_of(entry.first.source()), std::string(entry.first.str()));
    std::stable_sort(found.begin(), found.end());
    std::vector<std::string> out;
    for (auto& f : found) out.push_back(std::move(f.second));
    return out;
  }

  /// A finite number; integers are accepted.
  std::optional<double> number(std::string_view key) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    const std::optional<double> v = as_double(*node);
    if (!v) wrong_type(key, *node, "a number");
    if (!std::isfinite(*v)) fail(key, "must be finite, got " + format_number(*v));
    return v;
  }

  std::optional<double> positive(std::string_view key) const { return bounded(key, true); }
  std::optional<double> non_negative(std::string_view key) const { return bounded(key, false); }

  /// An integer in [min, largest Int]; floats are refused (counts are never fractional).
  template <class Int>
  std::optional<Int> integer(std::string_view key, Int min) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    if (!node->is_integer()) wrong_type(key, *node, "an integer");
    const std::int64_t v = node->as_integer()->get();
    if (v < min || v > std::numeric_limits<Int>::max()) {
      fail(key, "must be an integer ≥ " + std::to_string(min) + ", got " + std::to_string(v));
    }
    return static_cast<Int>(v);
  }

  std::optional<Vec3> vec3(std::string_view key) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    const toml::array* array = node->as_array();
    if (!array || array->size() != 3) wrong_type(key, *node, "an array of 3 numbers");
    Vec3 v;
    for (std::size_t i = 0; i < 3; ++i) {
      const std::optional<double> x = as_double(*array->get(i));
      if (!x) {
        fail(key, "expected an array of 3 numbers, element " + std::to_string(i) + " is " +
                      describe(*array->get(i)));
      }
      if (!std::isfinite(*x)) fail(key, "components must be finite");
      v[static_cast<Eigen::Index>(i)] = *x;
    }
    return v;
  }

  std::optional<Vec3> positive_vec3(std::string_view key) const {
    const std::optional<Vec3> v = vec3(key);
    if (v && !(v->array() > 0).all()) fail(key, "every component must be > 0");
    return v;
  }

  /// A nonzero vector, normalised on reading.
  std::optional<Vec3> direction(std::string_view key) const {
    const std::optional<Vec3> v = vec3(key);
    if (!v) return std::nullopt;
    if (v->norm() == 0) fail(key, "must be a nonzero vector");
    return v->normalized();
  }

  /// A string that must be one of `names`; nullptr when absent.
  template <class E>
  const Named<E>* named(std::string_view key, const NameTable<E>& names) const {
    const std::optional<std::string> value = text(key);
    if (!value) return nullptr;
    for (const Named<E>& n : names) {
      if (n.name == *value) return &n;
    }
    fail(key, "unknown value '" + *value + "'", choice_hint(*value, names_of(names)));
  }

  /// The required `kind` key; checks the table's keys against that kind's list.
  template <class E>
  const Named<E>& kind(const NameTable<E>& kinds) const {
    const Named<E>* k = named("kind", kinds);
    if (!k) fail("kind", "missing required key", "accepted: " + joined(names_of(kinds)));
    const std::string kind_name(k->name);
    // A key of another kind (radius on a box) is a mix-up, not a typo: say so.
    const std::optional<std::string_view> extra = first_key_not_in(k->keys);
    const auto has_extra = [&](const Named<E>& other) { return contains(other.keys, *extra); };
    if (extra && std::any_of(kinds.begin(), kinds.end(), has_extra)) {
      fail(*extra, "'" + std::string(*extra) + "' does not apply to kind '" + kind_name + "'",
           "keys for kind '" + kind_name + "': " + joined(k->keys));
    }
    check_keys(k->keys, {}, " for kind '" + kind_name + "'");
    return *k;
  }

  template <class T>
  T required(std::string_view key, std::optional<T> value) const {
    if (!value) fail(key, "missing required key");
    return *std::move(value);
  }

 private:
  /// The earliest (in file order) key of this table not in `allowed`.
  std::optional<std::string_view> first_key_not_in(const Keys& allowed) const {
    std::optional<std::string_view> first;
    for (const auto& entry : *table_) {
      const std::string_view key = entry.first.str();
      if (contains(allowed, key)) continue;
      if (!first || line_of_key(key) < line_of_key(*first)) first = key;
    }
    return first;
  }

  [[noreturn]] void wrong_type(std::string_view key, const toml::node& node,
                               const std::string& expected) const {
    fail(key, "expected " + expected + ", got " + describe(node));
  }

  std::optional<double> bounded(std::string_view key, bool strictly_positive) const {
    const std::optional<double> v = number(key);
    if (v && (strictly_positive ? !(*v > 0) : !(*v >= 0))) {
      fail(key, std::string("must be ") + (strictly_positive ? "> 0" : "≥ 0") + ", got " +
                    format_number(*v));
    }
    return v;
  }

  template <class E>
  static Keys names_of(const NameTable<E>& names) {
    Keys keys;
    for (const Named<E>& n : names) keys.push_back(n.name);
    return keys;
  }

  const toml::table* table_;
  std::string path_;
  const std::string* source_;
};

}  // namespace vb::scene_toml
