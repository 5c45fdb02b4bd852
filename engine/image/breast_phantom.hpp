#pragma once
/// A deterministic synthetic supine breast CT with its tissue label map (docs/PHANTOM.md).
/// Coordinates are DICOM LPS metres: x → patient left, y → posterior, z → superior. The breast
/// mound protrudes anteriorly (−y) from the chest wall, whose front is the plane y = 0; the
/// breast is centred at x = z = 0.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "engine/image/image_volume.hpp"

namespace vb {

/// Label values of Phantom::labels (fixed; also the index into Phantom::label_names).
namespace phantom_label {
inline constexpr int air = 0;
inline constexpr int skin = 1;
inline constexpr int adipose = 2;
inline constexpr int fibroglandular = 3;
inline constexpr int muscle = 4;  ///< pectoral muscle and the chest-wall soft tissue around the ribs
inline constexpr int bone = 5;    ///< ribs
inline constexpr int tumour = 6;
}  // namespace phantom_label

struct PhantomTumour {
  std::string type;                                  ///< "idc", "dcis" or "fibroadenoma"
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();  ///< LPS (m); must lie inside the breast mound
  double radius_m = 0.0;
};

struct PhantomSpec {
  std::uint64_t seed = 1;               ///< fixes the glandular texture and the image noise
  double spacing_m = 0.002;             ///< isotropic voxel edge, (0, 0.01] m
  /// Voxel edges along x, y, z (m, each in (0, 0.01]) when set (all three > 0); else spacing_m
  /// on every axis. E.g. a planning CT's 0.98 × 0.98 × 2.5 mm.
  Eigen::Vector3d spacing_xyz_m = Eigen::Vector3d::Zero();
  /// Voxels along x, y, z when set (all three > 0): a field of view of that size, centred on
  /// the breast in x and z and on the mound and chest-wall slab in y, which it must cover;
  /// else the smallest grid covering them with fov_margin_m of air.
  std::array<int, 3> dims{0, 0, 0};
  std::vector<PhantomTumour> tumours;   ///< spheres painted over soft tissue, later ones on top

  /// Breast mound semi-axes (m): x half-width, y anterior depth (flattened by gravity when
  /// supine), z half-height. The mound is the half-ellipsoid y < 0 centred at the origin.
  Eigen::Vector3d breast_radii_m{0.07, 0.04, 0.065};
  double skin_thickness_m = 0.002;      ///< at least one voxel whatever the spacing
  double pectoral_thickness_m = 0.010;  ///< muscle between y = 0 and the front of the ribs
  double rib_half_thickness_m = 0.004;  ///< rib cross-section semi-axis along y
  double rib_half_height_m = 0.007;     ///< rib cross-section semi-axis along z
  double rib_pitch_m = 0.025;           ///< superior–inferior distance between rib axes (one at z = 0)
  double chest_wall_depth_m = 0.030;    ///< torso slab kept in the field of view, posterior to y = 0
  double fov_margin_m = 0.015;          ///< field of view beyond the mound in x, −y and z
  double noise_sigma_hu = 10.0;         ///< standard deviation of the Gaussian image noise (HU)
};

struct Phantom {
  ImageVolume ct;       ///< Hounsfield units, modality "CT"
  ImageVolume labels;   ///< phantom_label values, modality "LABEL"; same dims and affine as ct
  std::vector<std::string> label_names;  ///< label value → name ("air", "skin", "adipose", ...)
};

/// Builds the phantom. Same spec (seed included) → bit-identical volumes. Throws vb::Error for
/// an invalid spec (spacing, geometry knobs, tumour type, radius or centre).
Phantom make_breast_phantom(const PhantomSpec& spec);

/// Parses the command-line form "type,x,y,z,radius" with lengths in millimetres (LPS), e.g.
/// "idc,15,-25,10,8", into metres. Throws vb::Error naming the bad field.
PhantomTumour parse_tumour_option(const std::string& text);

}  // namespace vb
