#pragma once
/// Which slices of a source image a pulled-back (resampled) image reads: what a derived DICOM
/// series lists per slice in its SourceImageSequence.
#include <utility>
#include <vector>

#include "engine/image/image_volume.hpp"

namespace vb {

/// For each k slice of `grid` (the resampled image), the source slices [first, last] that
/// trilinear sampling at y + d(y) reads for its voxels y; the source shares `grid`'s voxel grid.
/// pull_back_lps_m: 3 floats (LPS metres) per voxel of `grid`, i fastest. Points outside the
/// source are clamped to its first or last slice.
std::vector<std::pair<int, int>> source_slices_read(const ImageVolume& grid, const std::vector<float>& pull_back_lps_m);

}  // namespace vb
