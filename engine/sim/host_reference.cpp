#include "engine/sim/host_reference.hpp"

#include <cmath>

#include <Eigen/Dense>

#include "engine/lattice/dual_cells.hpp"
#include "engine/material/biphasic_spring.hpp"
#include "engine/material/hyperelastic.hpp"
#include "engine/material/linear_spring.hpp"

namespace vb {

namespace {

/// The law of a kernel material-table row (law 0 → none: linear springs; 3: biphasic springs).
std::optional<HyperelasticLaw> law_of_row(const std::array<double, 12>& row) {
  if (row[0] == 0 || row[0] == 3) return std::nullopt;
  std::vector<double> mu, alpha;
  for (int p = 0; p < int(row[1]); ++p) {
    mu.push_back(row[2 + p]);
    alpha.push_back(row[5 + p]);
  }
  return ogden(mu, alpha, row[8]);
}

/// The biphasic spring of a material-table row (law 3: c3 in slot 9, εc in slot 10).
std::optional<BiphasicSpring> biphasic_of_row(const std::array<double, 12>& row) {
  if (row[0] != 3) return std::nullopt;
  return biphasic_spring(row[9], row[10]);
}

}  // namespace


std::array<double, 26> connection_stiffness(const Lattice& lattice, const std::vector<double>& E,
                                            std::size_t e) {
  const auto nb = lattice.neighbours(e);
  std::array<double, 26> k{};
  for (int d = 0; d < 26; ++d)
    if (nb[d] >= 0) k[d] = linear_spring::stiffness(d, lattice.spacing_m, E[e], E[nb[d]]);
  return k;
}

HostReference::HostReference(const Lattice& lattice, const ElementArrays& elements, const Scene& scene)
    : u(elements.displacement_m),
      v(elements.displacement_m.size(), 0.0),
      lattice_(lattice),
      el_(elements),
      gravity_(lattice.rotation.transpose() * (scene.gravity.active ? scene.gravity.acceleration_m_s2 : Vec3::Zero())),
      damping_(scene.solver.damping_per_s),
      hourglass_(scene.solver.hourglass),
      dashpot_ratio_(scene.solver.dashpot_ratio),
      integrator_(scene.solver.integrator) {
  for (const auto& row : elements.material_table) {
    laws_.push_back(law_of_row(row));
    biphasic_.push_back(biphasic_of_row(row));
  }
  for (std::size_t e = 0; e < lattice.element_count(); ++e) {
    neighbours_.push_back(lattice.neighbours(e));
    stiffness_.push_back(connection_stiffness(lattice, elements.youngs_modulus_pa, e));
  }
  if (elements.hyperelastic) cells_ = dual_cells();
}

void HostReference::element_stresses(const std::vector<double>& u, std::vector<Eigen::Matrix3d>& F,
                                     std::vector<Eigen::Matrix3d>& Q) const {
  const std::size_t n = lattice_.element_count();
  const double h = lattice_.spacing_m;
  const auto& offsets = neighbour_offsets();
  F.assign(n, Eigen::Matrix3d::Identity());
  Q.assign(n, Eigen::Matrix3d::Zero());
  for (std::size_t e = 0; e < n; ++e) {
    const auto& law = laws_[lattice_.tissue_of_element[e]];
    if (!law) continue;
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero(), B = Eigen::Matrix3d::Zero();
    for (int d = 0; d < 26; ++d) {
      if (neighbours_[e][d] < 0) continue;
      const std::size_t j = std::size_t(neighbours_[e][d]);
      const Vec3 dX(offsets[d][0], offsets[d][1], offsets[d][2]);
      const Vec3 dx = h * dX + Vec3(u[3 * j] - u[3 * e], u[3 * j + 1] - u[3 * e + 1], u[3 * j + 2] - u[3 * e + 2]);
      A += dx * dX.transpose();
      B += dX * dX.transpose();
    }
    if (B.determinant() < 0.5) continue;  // as the kernel: neighbours do not span 3-D
    const Eigen::Matrix3d Bi = B.inverse();
    F[e] = A * Bi / h;
    HyperelasticLaw isochoric = *law;  // the volumetric energy is the dual cells' (below)
    isochoric.bulk_modulus_pa = 0;
    Q[e] = dual_volume_fraction(neighbours_[e]) * h * first_piola(isochoric, F[e]) * Bi;  // V = w·h³
  }
}

std::vector<HostReference::DualCell> HostReference::dual_cells() const {
  // the cell whose lowest corner is element e: its corners e + (i, j, k), i, j, k ∈ {0, 1}
  const auto& offsets = neighbour_offsets();
  std::array<int, 8> direction{};  // neighbour index of corner (i, j, k), i + 2j + 4k ≥ 1
  for (int d = 0; d < 26; ++d) {
    const auto& o = offsets[d];
    if (o[0] >= 0 && o[1] >= 0 && o[2] >= 0) direction[o[0] + 2 * o[1] + 4 * o[2]] = d;
  }
  std::vector<DualCell> cells;
  for (std::size_t e = 0; e < lattice_.element_count(); ++e) {
    DualCell c;
    c.corner[0] = e;
    bool complete = true;
    for (int a = 1; a < 8 && complete; ++a) {
      const std::int32_t j = neighbours_[e][direction[a]];
      complete = j >= 0;
      c.corner[a] = std::size_t(j);
    }
    if (!complete) continue;
    for (const std::size_t a : c.corner) {
      const auto& law = laws_[lattice_.tissue_of_element[a]];
      if (law) c.bulk_modulus_pa += law->bulk_modulus_pa / 8;
    }
    if (c.bulk_modulus_pa > 0) cells.push_back(c);
  }
  return cells;
}

TrilinearVolume HostReference::cell_volume(const DualCell& c, const std::vector<double>& u) const {
  std::array<Vec3, 8> x;  // lattice frame, relative to corner 0's rest position
  for (int a = 0; a < 8; ++a) {
    const std::size_t e = c.corner[a];
    x[a] = lattice_.spacing_m * Vec3(a & 1, (a >> 1) & 1, (a >> 2) & 1) + Vec3(u[3 * e], u[3 * e + 1], u[3 * e + 2]);
  }
  return trilinear_volume(x);
}

double HostReference::elastic_energy(const std::vector<double>& u) const {
  const double h = lattice_.spacing_m, V0 = h * h * h;
  double energy = 0;
  if (!el_.hyperelastic) return energy;
  std::vector<Eigen::Matrix3d> F, Q;
  element_stresses(u, F, Q);
  for (std::size_t e = 0; e < lattice_.element_count(); ++e) {
    const auto& law = laws_[lattice_.tissue_of_element[e]];
    if (!law) continue;  // a strand without a fit has F = I: no energy
    HyperelasticLaw isochoric = *law;
    isochoric.bulk_modulus_pa = 0;
    energy += dual_volume_fraction(neighbours_[e]) * V0 * strain_energy(isochoric, F[e]);
  }
  for (const DualCell& c : cells_) {
    const double J = cell_volume(c, u).volume_m3 / V0;
    energy += V0 * 0.5 * c.bulk_modulus_pa * (J - 1) * (J - 1);
  }
  return energy;
}

std::vector<double> HostReference::lattice_forces(const std::vector<double>& u,
                                                  const std::vector<double>& v) const {
  const std::size_t n = lattice_.element_count();
  const auto& offsets = neighbour_offsets();
  const double h = lattice_.spacing_m;
  std::vector<Eigen::Matrix3d> F, Q;
  if (el_.hyperelastic) element_stresses(u, F, Q);
  const auto hyper = [&](std::size_t e) { return el_.hyperelastic && laws_[lattice_.tissue_of_element[e]].has_value(); };
  std::vector<double> f(3 * n, 0.0);
  for (std::size_t e = 0; e < n; ++e) {
    const Vec3 ue(u[3 * e], u[3 * e + 1], u[3 * e + 2]), ve(v[3 * e], v[3 * e + 1], v[3 * e + 2]);
    Vec3 fe = Vec3::Zero(), own_offsets = Vec3::Zero();
    for (int d = 0; d < 26; ++d) {
      const double k = stiffness_[e][d];
      if (k == 0) continue;
      const std::size_t j = neighbours_[e][d];
      const Vec3 hd = h * Vec3(offsets[d][0], offsets[d][1], offsets[d][2]);
      const Vec3 uj(u[3 * j], u[3 * j + 1], u[3 * j + 2]), vj(v[3 * j], v[3 * j + 1], v[3 * j + 2]);
      const Vec3 r = hd + (uj - ue);
      const double len = r.norm(), rest = hd.norm();
      const Vec3 nrm = r / len;
      // Each end adds half a spring; a hyperelastic end's rest length is its affine prediction,
      // a biphasic end pulls with ½·k·L·g(ε) of its own tissue's law.
      const auto spring_end = [&](std::size_t a) {
        const auto& spring = biphasic_[lattice_.tissue_of_element[a]];
        return spring ? 0.5 * k * rest * spring->normalised_force((len - rest) / rest) : 0.5 * k * (len - rest);
      };
      double magnitude = hyper(e) ? hourglass_ * k * (len - (F[e] * hd).norm()) : spring_end(e);
      magnitude += hyper(j) ? hourglass_ * k * (len - (F[j] * hd).norm()) : spring_end(j);
      if (hyper(j)) fe += Q[j] * hd;
      own_offsets += hd;
      const double inv_mass_sum = el_.inverse_mass[e] + el_.inverse_mass[j];
      if (dashpot_ratio_ > 0 && inv_mass_sum > 0)
        magnitude += 2 * dashpot_ratio_ * std::sqrt(k / inv_mass_sum) * (vj - ve).dot(nrm);
      fe += magnitude * nrm;
    }
    if (hyper(e)) fe += Q[e] * own_offsets;
    for (int c = 0; c < 3; ++c) f[3 * e + c] = fe[c];
  }
  // The dual cells' volumetric energy V0·κ_c/2·(V/V0 − 1)², scattered to each cell's 8 corners.
  const double V0 = h * h * h;
  for (const DualCell& c : cells_) {
    const TrilinearVolume cell = cell_volume(c, u);
    const double pressure = c.bulk_modulus_pa * (cell.volume_m3 / V0 - 1);
    for (int a = 0; a < 8; ++a)
      for (int k = 0; k < 3; ++k) f[3 * c.corner[a] + k] -= pressure * cell.gradient_m2[a][k];
  }
  return f;
}

std::vector<double> HostReference::acceleration(const std::vector<double>& u,
                                                const std::vector<double>& v) const {
  std::vector<double> a = lattice_forces(u, v);
  for (std::size_t e = 0; e < lattice_.element_count(); ++e)
    for (int c = 0; c < 3; ++c) {
      double& ac = a[3 * e + c];
      ac = el_.inverse_mass[e] == 0 ? 0.0 : ac * el_.inverse_mass[e] + gravity_[c] - damping_ * v[3 * e + c];
    }
  return a;
}

void HostReference::step(double dt, int steps) {
  for (int s = 0; s < steps; ++s) {
    const std::vector<double> a = acceleration(u, v);
    if (integrator_ == Integrator::SymplecticEuler) {
      for (std::size_t i = 0; i < u.size(); ++i) {
        v[i] += dt * a[i];
        u[i] += dt * v[i];
      }
      continue;
    }
    std::vector<double> up(u.size()), vp(v.size());
    for (std::size_t i = 0; i < u.size(); ++i) {
      up[i] = u[i] + dt * v[i];
      vp[i] = v[i] + dt * a[i];
    }
    const std::vector<double> ap = acceleration(up, vp);
    for (std::size_t i = 0; i < u.size(); ++i) {
      u[i] += 0.5 * dt * (v[i] + vp[i]);
      v[i] += 0.5 * dt * (a[i] + ap[i]);
    }
  }
}

}  // namespace vb
