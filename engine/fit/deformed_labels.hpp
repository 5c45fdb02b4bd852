#pragma once
/// The model's tissues after a simulated posture change, as a label map: the observation a
/// validation of label-map fitting starts from (docs/FIT.md, "Observation from a label map").
#include <vector>

#include "engine/image/image_volume.hpp"
#include "engine/lattice/lattice.hpp"

namespace vb {

/// A label map on a grid aligned with the lattice, `subdivide` voxels per lattice spacing along
/// each axis, padded to hold the moved body. Each voxel is pulled back through the posture change
/// (x = y − u(x), a fixed point with u interpolated trilinearly between element centres and
/// extended a few voxels past the body) and takes `value_of_tissue` of the element whose voxel x
/// lies in (0: none).
ImageVolume deformed_label_map(const Lattice& lattice, const std::vector<double>& change_m,
                               const std::vector<int>& value_of_tissue, int subdivide);

}  // namespace vb
