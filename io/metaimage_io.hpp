#pragma once
/// Displacement fields as MetaImage (`.mha`): ITK's own format, read the same way by every ITK
/// version (plastimatch, elastix/transformix, ANTs, 3D Slicer, SimpleITK). LPS millimetres, as
/// ITK holds them in memory, so no reader converts anything. Layout: docs/FORMATS.md, "MetaImage".
#include <functional>
#include <string>
#include <vector>

#include "engine/image/image_volume.hpp"

namespace vb {

/// Writes a displacement field u on the voxels of `grid` (its values are ignored):
/// `displacement_lps_m` holds 3 floats (LPS metres) per voxel, i fastest. The file is one `.mha`
/// (text header, then the voxels) with ElementType MET_FLOAT, ElementNumberOfChannels 3,
/// components LPS in mm, the grid's origin, spacing and direction (an orthonormal direction
/// matrix: a sheared affine is refused, as ITK has no place for it), the data zlib-compressed.
/// u maps a point x of the grid to x + u(x). Throws vb::Error naming the file and the voxel for
/// a non-finite value. The file appears atomically (AtomicOutput).
/// `progress` is told the fraction written, from the calling thread.
void write_metaimage_displacement(const std::string& path, const ImageVolume& grid,
                                  const std::vector<float>& displacement_lps_m,
                                  const std::function<void(double)>& progress = {});

}  // namespace vb
