#pragma once
/// Double-precision host implementation of the lattice forces and integrators: the reference
/// the OpenCL kernels are tested against, and the source of per-connection stiffness for the
/// time-step bound. Deliberately plain loops; not for production runs. Vectors (u, v, forces)
/// are in the lattice frame (equal to the world frame for axis-aligned lattices).
#include <array>
#include <vector>

#include <optional>

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
  /// Advances `steps` steps of the scene's integrator (gravity, damping; no indenter).
  void step(double dt, int steps);

  std::vector<double> u, v;  ///< n×3 state (m, m/s)

 private:
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
};

}  // namespace vb
