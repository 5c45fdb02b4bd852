#pragma once
/// Scene files (TOML, SI units) → vb::Scene. Strict: unknown keys, wrong types and values out of
/// range are vb::Error naming the file, line and dotted key, so a typo never silently changes
/// physics. The format is documented in docs/SCENE.md.
#include <string>
#include <vector>

#include "engine/scene/scene.hpp"
#include "io/scene_overrides.hpp"

namespace vb {

/// Reads and parses the scene file at `path`; Scene::source_path is `path`.
/// Throws vb::Error when the file cannot be read or the scene is invalid.
Scene parse_scene_file(const std::string& path);

/// As parse_scene_file, with `overrides` (dotted keys, docs/SWEEP.md "Keys") applied to the file's
/// text first; Scene::source_text is the edited text. Throws vb::Error naming the key when an
/// override cannot be applied, and as parse_scene_file when the edited scene is invalid.
Scene parse_scene_file(const std::string& path, const std::vector<SceneOverride>& overrides);

/// Parses scene text; `source_name` (e.g. the file name) is used in error locations.
/// Scene::source_text is `text`; Scene::source_path is left empty.
Scene parse_scene_text(const std::string& text, const std::string& source_name);

/// How an image model's DVF files are written: `[output]` dvf_nifti and dvf_dicom (docs/SCENE.md).
struct DvfFileOptions {
  bool legacy_nifti = false;  ///< NIfTI DVFs in ITK's legacy layout (intent 1007, LPS)
  bool dicom = true;          ///< dvf_inverse.dcm (only with warped_ct_dicom)
};

/// The scene's DVF file options, read from its text (parse_scene_text has checked them).
DvfFileOptions dvf_file_options(const Scene& scene);

/// Dotted keys whose values are file paths, relative to the scene file's folder when relative
/// (parse_scene_file resolves them): "model.image", "model.labels".
const std::vector<std::string>& scene_path_keys();

}  // namespace vb
