#pragma once
/// A recorded indenter trajectory (docs/SCENE.md, [[indenter]] path): a CSV with the header
/// time_s,x_mm,y_mm,z_mm and at least two rows of strictly increasing times; positions in mm at
/// the file boundary, metres inside.
#include <string>
#include <vector>

#include "engine/scene/scene.hpp"

namespace vb {

/// Reads the knots; throws vb::Error naming the file, the line and the problem.
std::vector<PathKnot> read_indenter_path_csv(const std::string& path);

}  // namespace vb
