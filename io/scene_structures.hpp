#pragma once
/// The `model.structures` keys of a scene (docs/SCENE.md, "CT image models"): an RTSTRUCT as
/// the CT's classification, read from the scene's text (checked when the scene was parsed).
#include <map>
#include <string>
#include <vector>

#include "engine/scene/scene.hpp"

namespace vb {

struct StructureSpec {
  std::string path;                               ///< the RTSTRUCT file ("" when the scene has none)
  std::map<std::string, std::string> table;       ///< ROI name → tissue name ("ignore": left out)
  std::vector<std::string> priority;              ///< overlapping ROIs: these names, first wins
};

/// The scene's structures, the path resolved against the scene file's folder when relative.
StructureSpec scene_structures(const Scene& scene);

}  // namespace vb
