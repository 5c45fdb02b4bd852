#pragma once
/// Per-element strain and stress measures from the final displacement (host, double).
#include <vector>

#include "engine/lattice/lattice.hpp"
#include "engine/sim/run_result.hpp"

namespace vb {

/// Deformation gradient of an element by least squares over its existing connections:
/// F = (Σ Δx ΔXᵀ)(Σ ΔX ΔXᵀ)⁻¹, exact for affine motion and valid at boundaries. Identity when the
/// neighbours do not span 3-D. `u` is n×3 (m), world frame; F is in the world frame.
Eigen::Matrix3d deformation_gradient(const Lattice& lattice, const std::vector<double>& u, std::size_t element);

/// Fills state.volumetric_strain (det F − 1), state.equivalent_strain (von Mises equivalent of
/// the Green-Lagrange strain) and state.von_mises_stress_pa (linear lattice: λ = μ = 0.4·E) from
/// state.displacement_m. Returns the volume change fraction Σ(J − 1)/n (equal voxel volumes).
double compute_element_measures(const Lattice& lattice, const std::vector<double>& youngs_modulus_pa,
                                FinalState& state);

}  // namespace vb
