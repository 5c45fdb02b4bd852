#include "engine/results/element_measures.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace vb {

Eigen::Matrix3d deformation_gradient(const Lattice& lattice, const std::vector<double>& u, std::size_t e) {
  const auto& offsets = neighbour_offsets();
  const auto nb = lattice.neighbours(e);
  const double h = lattice.spacing_m;
  const Eigen::Vector3d ue(u[3 * e], u[3 * e + 1], u[3 * e + 2]);
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero(), B = Eigen::Matrix3d::Zero();
  for (int d = 0; d < 26; ++d) {
    if (nb[d] < 0) continue;
    const std::size_t j = std::size_t(nb[d]);
    const Eigen::Vector3d dX = h * (lattice.rotation * Eigen::Vector3d(offsets[d][0], offsets[d][1], offsets[d][2]));
    const Eigen::Vector3d dx = dX + Eigen::Vector3d(u[3 * j], u[3 * j + 1], u[3 * j + 2]) - ue;
    A += dx * dX.transpose();
    B += dX * dX.transpose();
  }
  Eigen::FullPivLU<Eigen::Matrix3d> lu(B);
  if (lu.rank() < 3) return Eigen::Matrix3d::Identity();
  return A * lu.inverse();
}

FoldCheck check_folding(const Lattice& lattice, const std::vector<double>& u, const std::vector<double>& inverse_mass) {
  FoldCheck c;
  for (std::size_t e = 0; e < lattice.element_count(); ++e) {
    if (inverse_mass[e] == 0) continue;
    const double J = deformation_gradient(lattice, u, e).determinant();
    c.min_det_f = std::min(c.min_det_f, J);
    if (J <= 0) ++c.inverted_elements;
  }
  return c;
}

double compute_element_measures(const Lattice& lattice, const std::vector<double>& E, FinalState& st) {
  const std::size_t n = lattice.element_count();
  st.volumetric_strain.assign(n, 0.0);
  st.equivalent_strain.assign(n, 0.0);
  st.von_mises_stress_pa.assign(n, 0.0);
  double volume_change = 0;
  for (std::size_t e = 0; e < n; ++e) {
    const Eigen::Matrix3d F = deformation_gradient(lattice, st.displacement_m, e);
    const Eigen::Matrix3d strain = 0.5 * (F.transpose() * F - Eigen::Matrix3d::Identity());
    const Eigen::Matrix3d dev = strain - strain.trace() / 3.0 * Eigen::Matrix3d::Identity();
    const double lame = 0.4 * E[e];  // λ = μ = 0.4·E for the ν = 1/4 lattice
    const Eigen::Matrix3d stress = lame * strain.trace() * Eigen::Matrix3d::Identity() + 2 * lame * strain;
    const Eigen::Matrix3d sdev = stress - stress.trace() / 3.0 * Eigen::Matrix3d::Identity();
    st.volumetric_strain[e] = F.determinant() - 1.0;
    st.equivalent_strain[e] = std::sqrt(2.0 / 3.0 * dev.squaredNorm());
    st.von_mises_stress_pa[e] = std::sqrt(1.5 * sdev.squaredNorm());
    volume_change += st.volumetric_strain[e];
  }
  return n ? volume_change / double(n) : 0.0;
}

}  // namespace vb
