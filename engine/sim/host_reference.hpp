#pragma once
/// Double-precision host implementation of the lattice forces and integrators: the reference
/// the OpenCL kernels are tested against, and the source of per-connection stiffness for the
/// time-step bound. Deliberately plain loops; not for production runs. Vectors (u, v, forces)
/// are in the lattice frame (equal to the world frame for axis-aligned lattices).
#include <array>
#include <vector>

#include <optional>

#include "engine/lattice/dual_cells.hpp"
#include "engine/lattice/lattice.hpp"
#include "engine/material/biphasic_spring.hpp"
#include "engine/material/hyperelastic.hpp"
#include "engine/scene/scene.hpp"
#include "engine/sim/element_setup.hpp"

namespace vb {

/// Spring constants (N/m) of an element's 26 connections (0 where absent).
std::array<double, 26> connection_stiffness(const Lattice& lattice, const std::vector<double>& E_pa,
                                            std::size_t element);

class HostReference {
 public:
  HostReference(const Lattice& lattice, const ElementArrays& elements, const Scene& scene);

  /// Lattice spring + dashpot force on every element (n×3, N) at displacement u, velocity v.
  std::vector<double> lattice_forces(const std::vector<double>& u, const std::vector<double>& v) const;
  /// Per-element deformation gradient F and Q = V·P·B⁻¹ (identity / zero for spring tissues).
  void element_stresses(const std::vector<double>& u, std::vector<Eigen::Matrix3d>& F,
                        std::vector<Eigen::Matrix3d>& Q) const;
  /// Elastic energy (J) of the hyperelastic tissue at displacement u: Σ_e w_e·h³·W_iso(F_e) over
  /// its elements plus Σ_c h³·κ_c/2·(J_c − 1)² over the complete dual cells with hyperelastic
  /// corners (J_c = V_c/h³, the trilinear cell's volume). The stress and volumetric forces of
  /// lattice_forces are its negative gradient; the hourglass springs and dashpots have none here.
  double elastic_energy(const std::vector<double>& u) const;
  /// Advances `steps` steps of the scene's integrator (gravity, damping; no indenter).
  void step(double dt, int steps);

  std::vector<double> u, v;  ///< n×3 state (m, m/s)

 private:
  /// A complete dual cell: corners (i, j, k) ∈ {0, 1}³ at corner[i + 2j + 4k], κ_c = ⅛·Σ κ
  struct DualCell {
    std::array<std::size_t, 8> corner{};
    double bulk_modulus_pa = 0;
  };
  std::vector<DualCell> dual_cells() const;
  TrilinearVolume cell_volume(const DualCell& c, const std::vector<double>& u) const;
  std::vector<double> acceleration(const std::vector<double>& u, const std::vector<double>& v) const;
  const Lattice& lattice_;
  const ElementArrays& el_;
  std::vector<std::array<std::int32_t, 26>> neighbours_;
  std::vector<std::array<double, 26>> stiffness_;
  Vec3 gravity_;
  double damping_, hourglass_, dashpot_ratio_;
  std::vector<std::optional<HyperelasticLaw>> laws_;  ///< per tissue; empty for spring tissues
  std::vector<std::optional<BiphasicSpring>> biphasic_;  ///< per tissue; set for biphasic springs
  Integrator integrator_;
  std::vector<DualCell> cells_;  ///< complete dual cells with some hyperelastic corner
};

}  // namespace vb
