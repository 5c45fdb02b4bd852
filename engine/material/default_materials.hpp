#pragma once
/// Default tissue properties used when a scene names a tissue without giving [materials.X]
/// values. Sources and ranges: docs/MATERIALS.md. Scenes override any value.
#include <optional>
#include <string>
#include <vector>

#include "engine/scene/scene.hpp"

namespace vb {

/// The default material of a tissue name (adipose, fibroglandular, skin, muscle, bone, tumour,
/// idc, dcis, fibroadenoma), or nothing for other names.
std::optional<MaterialSpec> default_material(const std::string& tissue);

/// Names that have defaults, for messages.
std::vector<std::string> default_material_names();

}  // namespace vb
