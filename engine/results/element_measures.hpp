#pragma once
/// Per-element strain and stress measures from the final displacement (host, double).
#include <cmath>
#include <cstdint>
#include <vector>

#include "engine/lattice/lattice.hpp"
#include "engine/sim/run_result.hpp"

namespace vb {

/// Deformation gradient of an element by least squares over its existing connections:
/// F = (Σ Δx ΔXᵀ)(Σ ΔX ΔXᵀ)⁻¹, exact for affine motion and valid at boundaries. Identity when the
/// neighbours do not span 3-D. `u` is n×3 (m), world frame; F is in the world frame.
Eigen::Matrix3d deformation_gradient(const Lattice& lattice, const std::vector<double>& u, std::size_t element);

/// Folded elements: the spring lattice has no resistance to inversion, and a press that crushes
/// the layer under an indenter can push an element through its neighbours into a softer, folded
/// state (docs/PROBING.md, "Validity"); a force read from such a state is not the tissue's.
struct FoldCheck {
  double min_det_f = INFINITY;        ///< smallest det F over the free elements (INFINITY: none)
  std::int64_t inverted_elements = 0; ///< free elements with det F ≤ 0
};
/// det F of every free element (inverse_mass[e] ≠ 0; held elements are skipped), as
/// deformation_gradient. Used by `voxbreast probe` after each increment and by the haptic probe.
FoldCheck check_folding(const Lattice& lattice, const std::vector<double>& u, const std::vector<double>& inverse_mass);

/// Fills state.volumetric_strain (det F − 1), state.equivalent_strain (von Mises equivalent of
/// the Green-Lagrange strain) and state.von_mises_stress_pa (linear lattice: λ = μ = 0.4·E) from
/// state.displacement_m. Returns the volume change fraction Σ(J − 1)/n (equal voxel volumes).
double compute_element_measures(const Lattice& lattice, const std::vector<double>& youngs_modulus_pa,
                                FinalState& state);

}  // namespace vb
