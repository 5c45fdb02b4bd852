#pragma once
/// The voxel lattice: one mass element per occupied voxel, joined to its 26 neighbours.
/// Only occupied voxels are stored (compact arrays) plus a dense voxel → element index.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace vb {

/// A labelled voxel volume: label 0 is empty, label t ≥ 1 is tissue `tissue_names[t - 1]`.
struct LabelVolume {
  std::array<int, 3> dims{0, 0, 0};          ///< voxels along x, y, z
  double spacing_m = 0;                      ///< isotropic voxel edge (m)
  Eigen::Vector3d origin_m = Eigen::Vector3d::Zero();  ///< world centre of voxel (0, 0, 0) (m)
  /// world direction of each voxel axis (columns, orthonormal): identity for analytic shapes,
  /// the image's direction cosines for (possibly oblique) CT volumes
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  std::vector<std::uint8_t> labels;          ///< dims[0]·dims[1]·dims[2], x fastest
  std::vector<std::string> tissue_names;     ///< label t ≥ 1 → tissue_names[t - 1]

  std::size_t voxel_count() const { return labels.size(); }
  std::size_t linear_index(int i, int j, int k) const {
    return static_cast<std::size_t>(i) + static_cast<std::size_t>(dims[0]) *
                                             (static_cast<std::size_t>(j) +
                                              static_cast<std::size_t>(dims[1]) * k);
  }
};

struct Lattice {
  std::array<int, 3> dims{0, 0, 0};  ///< voxel grid the elements live on
  double spacing_m = 0;              ///< element spacing (m)
  Eigen::Vector3d origin_m = Eigen::Vector3d::Zero();  ///< world centre of voxel (0,0,0) (m)
  /// world direction of each lattice axis (columns, orthonormal). The simulator works in the
  /// lattice frame, where a world vector w is rotationᵀ·w.
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  std::vector<std::uint32_t> voxel_of_element;  ///< n_elements, linear voxel index (x fastest)
  std::vector<std::int32_t> element_of_voxel;   ///< dims product, -1 where empty
  std::vector<std::uint8_t> tissue_of_element;  ///< n_elements, index into tissue_names
  std::vector<std::string> tissue_names;
  std::size_t connection_count = 0;  ///< neighbour pairs (each pair counted once)

  std::size_t element_count() const { return voxel_of_element.size(); }
  std::array<int, 3> voxel_ijk(std::size_t element) const;
  /// rest (voxel-centre) position of an element (m)
  Eigen::Vector3d rest_position(std::size_t element) const;
  /// voxel index → world transform (4×4, m), voxel centres at integer indices
  Eigen::Matrix4d affine() const;
  /// element index of each of the 26 neighbours (neighbour_offsets() order), -1 where empty
  std::array<std::int32_t, 26> neighbours(std::size_t element) const;
};

/// The 26 neighbour offsets, ordered: 6 face, 12 edge (face diagonal), 8 corner (body diagonal).
const std::array<std::array<int, 3>, 26>& neighbour_offsets();

/// Builds the lattice of every non-empty voxel. `downsample` ≥ 1 merges downsample³ blocks of
/// voxels into one element carrying the majority tissue (empty wins ties with nothing; a block
/// is occupied when at least half of its voxels are).
Lattice build_lattice(const LabelVolume& volume, int downsample = 1);

}  // namespace vb
