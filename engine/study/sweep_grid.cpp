#include "engine/study/sweep_grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include "engine/error.hpp"

namespace vb {
namespace {

/// Splits at `separator` outside quotes and brackets, so [0, 0, -9.81] stays one item.
std::vector<std::string> split_top_level(const std::string& text, char separator) {
  std::vector<std::string> items(1);
  int depth = 0;
  char quote = 0;
  for (char c : text) {
    if (quote) {
      if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '[' || c == '{') {
      ++depth;
    } else if (c == ']' || c == '}') {
      --depth;
    } else if (c == separator && depth == 0) {
      items.emplace_back();
      continue;
    }
    items.back() += c;
  }
  return items;
}

std::string trimmed(std::string s) {
  const auto space = [](unsigned char c) { return std::isspace(c) != 0; };
  while (!s.empty() && space(s.back())) s.pop_back();
  s.erase(s.begin(), std::find_if_not(s.begin(), s.end(), space));
  return s;
}

/// A number as TOML writes it: an integer (digits, optional sign) or a float; nothing otherwise.
struct Number {
  double value = 0;
  bool integer = false;
};

std::optional<Number> parse_number(const std::string& text) {
  const std::string t = trimmed(text);
  if (t.empty()) return std::nullopt;
  const bool integer = t.find_first_not_of("+-0123456789") == std::string::npos;
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (end != t.c_str() + t.size() || !std::isfinite(v)) return std::nullopt;
  if (t.find_first_not_of("+-0123456789.eE") != std::string::npos) return std::nullopt;  // no hex, inf, nan
  return Number{v, integer};
}

/// A float rounded to 12 significant digits, written as a TOML float (always with '.' or 'e').
std::string float_text(double v) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.12g", v);
  std::string s = buffer;
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

std::vector<std::string> range_values(const std::string& spec, const std::string& where) {
  const std::vector<std::string> t = split_top_level(spec, ':');
  const std::string form = "a range is FROM:TO:N or FROM:TO:N:log, e.g. 0.01:0.03:5";
  if (t.size() != 3 && t.size() != 4) throw Error("malformed range '" + spec + "'", where, form);
  const std::optional<Number> from = parse_number(t[0]), to = parse_number(t[1]), n = parse_number(t[2]);
  if (!from || !to) throw Error("range ends must be finite numbers, got '" + t[0] + "' and '" + t[1] + "'", where, form);
  if (!n || !n->integer || n->value < 2 || n->value > 1e6)
    throw Error("range count must be an integer from 2 to 1000000, got '" + t[2] + "'", where,
                "for one value write KEY=VALUE");
  const bool log = t.size() == 4 && trimmed(t[3]) == "log";
  if (t.size() == 4 && !log && trimmed(t[3]) != "lin")
    throw Error("unknown range spacing '" + t[3] + "'", where, "use lin (the default) or log");
  if (from->value == to->value) throw Error("range from " + t[0] + " to " + t[1] + " is empty", where, form);
  if (log && !(from->value > 0 && to->value > 0))
    throw Error("a log range needs FROM and TO > 0", where, form);
  const auto count = static_cast<std::size_t>(n->value);
  const double span = to->value - from->value;
  std::vector<std::string> values;
  const bool whole_steps = from->integer && to->integer && !log &&
                           std::fmod(std::abs(span), double(count - 1)) == 0 && std::abs(span) < 9e15;
  for (std::size_t i = 0; i < count; ++i) {
    const double f = double(i) / double(count - 1);
    if (whole_steps) {
      values.push_back(std::to_string(static_cast<long long>(from->value + span / double(count - 1) * double(i))));
      continue;
    }
    double v = log ? std::exp(std::log(from->value) + f * (std::log(to->value) - std::log(from->value)))
                   : from->value + span * f;
    if (i == 0) v = from->value;
    if (i + 1 == count) v = to->value;
    values.push_back(float_text(v));
  }
  return values;
}

/// KEY=FROM:... is a range when the text before the first ':' is a number.
bool looks_like_range(const std::string& spec) {
  const std::vector<std::string> t = split_top_level(spec, ':');
  return t.size() > 1 && parse_number(t[0]).has_value();
}

}  // namespace

SweepParameter parse_vary(const std::string& argument) {
  const std::string where = "--vary " + argument;
  const std::size_t eq = argument.find('=');
  const std::string example = "e.g. --vary materials.adipose.E=2000:6000:5 or --vary gravity.posture=prone,supine";
  if (eq == std::string::npos) throw Error("expected KEY=VALUES", where, example);
  SweepParameter p;
  p.key = trimmed(argument.substr(0, eq));
  if (!p.key.empty() && p.key[0] == '+') p.key = trimmed(p.key.substr(1)), p.add = true;
  if (p.key.empty()) throw Error("the key is empty", where, example);
  try {
    (void)split_scene_key(p.key);
  } catch (const Error& e) {
    throw Error(e.problem(), where, e.hint());
  }
  const std::string spec = argument.substr(eq + 1);
  const std::vector<std::string> items = split_top_level(spec, ',');
  if (items.size() == 1 && looks_like_range(spec)) {
    p.values = range_values(spec, where);
  } else {
    for (const std::string& item : items) {
      try {
        p.values.push_back(toml_value_text(item));
      } catch (const Error& e) {
        throw Error(e.problem(), where, e.hint());
      }
    }
  }
  for (std::size_t i = 0; i < p.values.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (p.values[i] == p.values[j])
        throw Error("value " + p.values[i] + " is listed twice", where, "each case must differ");
  return p;
}

SweepGrid::SweepGrid(std::vector<SweepParameter> parameters, std::size_t max_cases)
    : parameters_(std::move(parameters)) {
  for (std::size_t i = 0; i < parameters_.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j)
      if (split_scene_key(parameters_[i].key) == split_scene_key(parameters_[j].key))
        throw Error("key '" + parameters_[i].key + "' is varied twice", "--vary", "give each key once, with all its values");
    require(!parameters_[i].values.empty(), "key '" + parameters_[i].key + "' has no values", "--vary");
    if (size_ > max_cases / parameters_[i].values.size())
      throw Error("the grid has more than " + std::to_string(max_cases) + " cases", "--vary", "vary fewer values");
    size_ *= parameters_[i].values.size();
  }
}

std::vector<std::string> SweepGrid::values_of(std::size_t index) const {
  require(index < size_, "case index " + std::to_string(index) + " is outside the grid");
  std::vector<std::string> values(parameters_.size());
  for (std::size_t p = parameters_.size(); p-- > 0;) {
    const std::size_t n = parameters_[p].values.size();
    values[p] = parameters_[p].values[index % n];
    index /= n;
  }
  return values;
}

std::vector<SceneOverride> SweepGrid::overrides_of(std::size_t index) const {
  const std::vector<std::string> values = values_of(index);
  std::vector<SceneOverride> overrides;
  for (std::size_t p = 0; p < parameters_.size(); ++p)
    overrides.push_back({parameters_[p].key, values[p], parameters_[p].add});
  return overrides;
}

}  // namespace vb
