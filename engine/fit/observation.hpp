#pragma once
/// What a fit matches: observed element displacements of the posture change with their weights
/// (docs/FIT.md, "Observation").
#include <string>
#include <vector>

#include "engine/image/image_volume.hpp"
#include "engine/lattice/lattice.hpp"

namespace vb {

struct Observation {
  std::vector<double> displacement_m;  ///< n×3 observed displacement (m, world LPS)
  std::vector<double> weight_per_m2;   ///< n: 1/σ² of each component (1/m²); 0: not observed
  std::size_t observed_elements() const;
};

/// Samples a displacement field (3 floats per voxel of `grid`, LPS m) trilinearly at every
/// element's rest centre; elements outside the grid are not observed. Weight 1/sigma².
Observation observation_from_field(const Lattice& lattice, const ImageVolume& grid,
                                   const std::vector<float>& field_lps_m, double sigma_m);

/// Unobserves the elements whose centre's nearest mask voxel is 0 (or outside the mask).
void apply_mask(Observation& obs, const Lattice& lattice, const ImageVolume& mask);
/// Weights from an uncertainty image (mm, nearest voxel); non-positive values unobserve.
void apply_sigma_image(Observation& obs, const Lattice& lattice, const ImageVolume& sigma_mm);

struct Landmark {
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();         ///< in the model's image (LPS m)
  Eigen::Vector3d displacement_m = Eigen::Vector3d::Zero();  ///< where it moved to, minus point
  double sigma_m = 0;                                        ///< 0: the fit's sigma
};

/// Each landmark observes the element containing it (vb::Error for one outside the model or
/// two in one element).
Observation observation_from_landmarks(const Lattice& lattice, const std::vector<Landmark>& landmarks, double sigma_m);

/// Residual statistics of simulated against observed displacement over the observed elements.
struct ResidualStats {
  std::size_t elements = 0;
  double rms_m = 0, mean_m = 0, p95_m = 0, max_m = 0;
  double within_1mm = 0;  ///< fraction of elements with |simulated − observed| ≤ 1 mm
};
ResidualStats residual_stats(const Observation& obs, const std::vector<double>& simulated_m);
/// The same statistics of per-point distances (m), e.g. surface distances.
ResidualStats distance_stats(std::vector<double> distances_m);

}  // namespace vb
