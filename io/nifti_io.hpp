#pragma once
/// NIfTI reading and writing (nifti_clib), converting between the file's RAS world in millimetres
/// and VoxBreast's DICOM LPS world in metres. The rules are in docs/FORMATS.md, section "NIfTI".
#include <functional>
#include <string>
#include <vector>

#include "engine/image/image_volume.hpp"

namespace vb {

/// Reads a 3-D scalar NIfTI-1 or NIfTI-2 image (`.nii` or `.nii.gz`).
/// - World affine: the sform if sform_code > 0, else the qform if qform_code > 0, else
///   diag(pixdim) (no orientation in the file: voxel axes taken as R, A, S). The file's RAS world,
///   in the unit of xyzt_units (unknown = mm), becomes LPS metres: x and y rows negated, scaled.
/// - Values: scl_slope/scl_inter applied when the slope is finite and non-zero.
///   Types int8, uint8, int16, uint16, int32, uint32, float32, float64.
/// - modality: "LABEL" when intent_code is NIFTI_INTENT_LABEL, "" otherwise.
/// Throws vb::Error naming the path for a missing, unreadable, corrupt or truncated file, an
/// unsupported type, a 4-D or vector file, a non-positive or non-finite spacing, or a singular
/// affine.
ImageVolume read_nifti(const std::string& path);

/// Voxel type of a written NIfTI file.
enum class NiftiType { Int16, UInt8, Float32 };

/// Writes `image` as NIfTI-1, gzip-compressed for `.nii.gz`, plain for `.nii` (other extensions
/// are refused). sform and qform both carry the affine in RAS mm with code 1 (NIFTI_XFORM_
/// SCANNER_ANAT: the DICOM patient frame the image came from); the qform, a rotation by
/// definition, is the nearest rigid fit when the affine is sheared, so readers should (and
/// do) prefer the sform. xyzt_units = mm. Integer types round to nearest; a value outside the
/// type's range or not finite throws vb::Error rather than saturating. A "LABEL" modality is
/// written with intent NIFTI_INTENT_LABEL. The file appears atomically (AtomicOutput).
/// `progress` is told the fraction written, from the calling thread.
void write_nifti(const std::string& path, const ImageVolume& image, NiftiType type,
                 const std::function<void(double)>& progress = {});

/// How a displacement field's vectors are stored in a NIfTI file.
enum class NiftiDisplacementLayout {
  /// intent NIFTI_INTENT_DISPVECT (1006), components in the file's RAS frame: the NIfTI standard's
  /// displacement field, as ITK >= 5.4, 3D Slicer and nibabel read and write it
  DispVectRas,
  /// intent NIFTI_INTENT_VECTOR (1007), components LPS: ITK's layout before 5.4, the only one
  /// tools built on older ITK (plastimatch 1.9, elastix 5.0, ANTs before 2.5) read as a field
  VectorLps,
};

/// Writes a displacement field u on the voxels of `grid` (its values are ignored):
/// `displacement_lps_m` holds 3 floats (LPS metres) per voxel, i fastest. Stored as float32,
/// dims (nx, ny, nz, 1, 3), components in mm in the given layout (the standard one by default),
/// sform/qform as write_nifti. u maps a point x of the grid to x + u(x). Atomic like write_nifti.
void write_nifti_displacement(const std::string& path, const ImageVolume& grid,
                              const std::vector<float>& displacement_lps_m,
                              NiftiDisplacementLayout layout = NiftiDisplacementLayout::DispVectRas,
                              const std::function<void(double)>& progress = {});

/// The inverse of write_nifti_displacement: returns the grid (values empty, affine as
/// read_nifti) and fills `displacement_lps_m` (3 per voxel, LPS metres). Accepts dims
/// (nx, ny, nz, 1, 3) with intent DISPVECT (1006, components RAS, as written above) or VECTOR
/// (1007, components LPS: what ITK writes by default, e.g. ANTs warps); the components are in
/// the unit of xyzt_units. Throws vb::Error for any other layout or intent.
ImageVolume read_nifti_displacement(const std::string& path,
                                    std::vector<float>& displacement_lps_m);

}  // namespace vb
