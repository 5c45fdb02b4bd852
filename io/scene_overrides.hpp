#pragma once
/// Changes to scene-file values addressed by dotted key — `materials.adipose.E`,
/// `gravity.vector.3`, `track.1.point`, `device.torus.2.minor_radius` — made in the scene *text*,
/// so comments, order and every other byte stay as written, and the result still goes through
/// the strict scene parser (docs/SWEEP.md, "Keys").
#include <string>
#include <vector>

namespace vb {

struct SceneOverride {
  /// Dotted path. Array elements (also [[array]] tables) by 1-based index; a part with dots or
  /// spaces in double quotes: materials."my tissue".E
  std::string key;
  /// A TOML value: 0.02, 3000, "prone", true, [0.0, 0.0, -9.81]
  std::string value;
  /// Create the key (and missing tables) when the scene lacks it; without `add` a missing key is
  /// an error, so a typo never silently adds an unused value.
  bool add = false;
};

/// One `KEY=VALUE` setting from a command line (`simulate --set`): KEY a dotted key as above,
/// `+KEY` to add a key the scene lacks, VALUE one value as toml_value_text reads it (3000,
/// prone, [0, 0, -9.81]). Throws vb::Error naming the argument when it is malformed.
SceneOverride parse_scene_setting(const std::string& argument);

/// The parts of a dotted key; throws vb::Error for empty parts or an unclosed quote.
std::vector<std::string> split_scene_key(const std::string& key);

/// TOML text for a value given as a word on a command line: text that already is a TOML value
/// (3000, 1e-4, true, "prone", [0, 0, -9.81]) is kept as written; anything else becomes a
/// quoted string (prone → "prone"). Throws vb::Error for non-finite numbers and tables.
std::string toml_value_text(const std::string& word);

/// `text` (a scene file; `source_name` names it in errors) with `overrides` applied. Throws
/// vb::Error naming the key when it is missing (with "did you mean"), names a table, indexes
/// past an array's end, or overlaps another override, and when the value is not TOML.
/// The edited text is checked by parsing it again and comparing with the overrides applied to
/// the parsed tree, so a wrong edit is an error, never a silently different scene.
std::string apply_scene_overrides(const std::string& text, const std::string& source_name,
                                  const std::vector<SceneOverride>& overrides);

/// TOML text of a string value, quoted and escaped as TOML needs ("a \"b\"", 'C:\\x').
std::string toml_string_text(const std::string& value);

/// A value text as a table shows it: strings without their quotes ("prone" → prone), other
/// values as written.
std::string toml_value_plain(const std::string& value_text);

/// The string value at `key` in the scene text; empty when the key is absent or not a string.
std::string scene_string_value(const std::string& text, const std::string& source_name, const std::string& key);

}  // namespace vb
