#include "engine/sim/time_step.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>

#include "engine/error.hpp"
#include "engine/lattice/dual_cells.hpp"
#include "engine/material/linear_spring.hpp"
#include "engine/sim/parallel_chunks.hpp"
#include "engine/sim/triangle_contact.hpp"

namespace vb {

namespace {

/// Σ_b |n_a n_b| for each direction's unit vector n and row a: a connection's share of row a.
const std::array<std::array<double, 26>, 3>& row_weights() {
  static const std::array<std::array<double, 26>, 3> w = [] {
    std::array<std::array<double, 26>, 3> out{};
    const auto& offsets = neighbour_offsets();
    for (int d = 0; d < 26; ++d) {
      const Vec3 n = Vec3(offsets[d][0], offsets[d][1], offsets[d][2]).normalized();
      for (int a = 0; a < 3; ++a) out[a][d] = std::abs(n[a]) * n.cwiseAbs().sum();
    }
    return out;
  }();
  return w;
}

/// The Gershgorin row (N/m, the same for x, y and z) of the dual cells' volumetric energy at
/// element e (kernels/hyperelastic.cl, dual_cell_volumetric_force): a complete cell's stiffness at
/// rest is κ_c/h³·b·bᵀ with b = ∂V/∂x, whose 8 corner entries are (±1, ±1, ±1)·h²/4, so each of
/// its rows sums to κ_c/h³·(h²/4)·24·(h²/4) = 1.5·κ_c·h; κ_c = ⅛·Σ of its corners' κ (0 for
/// spring tissue).
double dual_cell_row(const Lattice& lattice, const ElementArrays& el, const std::array<std::int32_t, 26>& nb,
                     std::size_t e) {
  if (!el.hyperelastic) return 0;
  const auto kappa = [&](std::size_t a) { return el.material_table[lattice.tissue_of_element[a]][8]; };
  double row = 0;
  for (const std::uint32_t mask : octant_masks()) {
    double kappa_sum = kappa(e);
    bool complete = true;
    for (int d = 0; d < 26 && complete; ++d) {
      if (!(mask & (1u << d))) continue;
      complete = nb[d] >= 0;
      if (complete) kappa_sum += kappa(std::size_t(nb[d]));
    }
    if (complete) row += 1.5 * (kappa_sum / 8) * lattice.spacing_m;
  }
  return row;
}

/// Gershgorin row bounds of M⁻¹K and M⁻¹C (dashpots only) of a free element, over its 3 rows;
/// `extra_k` (N/m) is added to every stiffness row (triangle contact's penalty). Every simulator
/// and every new set of a fit's moduli computes these over the whole lattice, so the neighbours
/// are looked up once and the dashpots' square roots taken only where they act.
struct Rows {
  double omega_sq = 0, c_max = 0, k_max = 0;  ///< k_max: the largest stiffness row (N/m)
};
Rows element_rows(const Lattice& lattice, const ElementArrays& el, double dashpot_ratio, std::size_t e,
                  double extra_k = 0) {
  const auto nb = lattice.neighbours(e);
  const double h = lattice.spacing_m;
  std::array<double, 26> k{}, c{};  // spring stiffness (the stability modulus's) and dashpot
  for (int d = 0; d < 26; ++d) {
    if (nb[d] < 0) continue;
    const std::size_t j = std::size_t(nb[d]);
    k[d] = linear_spring::stiffness(d, h, el.stability_modulus_pa[e], el.stability_modulus_pa[j]);
    if (dashpot_ratio > 0) {  // the dashpots use the spring modulus
      const double reduced_mass = 1.0 / (el.inverse_mass[e] + el.inverse_mass[j]);
      c[d] = 2 * dashpot_ratio * std::sqrt(linear_spring::stiffness(d, h, el.youngs_modulus_pa[e], el.youngs_modulus_pa[j]) * reduced_mass);
    }
  }
  const auto& w = row_weights();
  const double volumetric = dual_cell_row(lattice, el, nb, e);
  Rows r;
  for (int a = 0; a < 3; ++a) {
    double k_row = volumetric, c_row = 0;
    for (int d = 0; d < 26; ++d) {
      if (k[d] == 0) continue;
      k_row += 2 * k[d] * w[a][d];
      c_row += 2 * c[d] * w[a][d];
    }
    r.k_max = std::max(r.k_max, k_row);
    r.omega_sq = std::max(r.omega_sq, (k_row + extra_k) * el.inverse_mass[e]);
    r.c_max = std::max(r.c_max, c_row * el.inverse_mass[e]);
  }
  return r;
}

}  // namespace

StabilityBounds stability_bounds(const Lattice& lattice, const ElementArrays& el, double dashpot_ratio,
                                 double global_damping, const std::vector<double>& extra_row_n_m) {
  const std::size_t n = lattice.element_count(), chunks = chunk_count(n);
  std::vector<Rows> most(chunks);  // each chunk's largest bounds: max is exact in any order
  for_chunks(n, chunks, [&](std::size_t chunk, std::size_t begin, std::size_t end) {
    Rows& m = most[chunk];
    for (std::size_t e = begin; e < end; ++e) {
      if (el.inverse_mass[e] == 0) continue;
      const Rows r = element_rows(lattice, el, dashpot_ratio, e, extra_row_n_m.empty() ? 0.0 : extra_row_n_m[e]);
      m.omega_sq = std::max(m.omega_sq, r.omega_sq);
      m.c_max = std::max(m.c_max, r.c_max);
    }
  });
  double omega_sq = 0, c_max = 0;
  for (const Rows& m : most) omega_sq = std::max(omega_sq, m.omega_sq), c_max = std::max(c_max, m.c_max);
  StabilityBounds b;
  b.omega_max = std::sqrt(omega_sq);
  b.damping_max = c_max + global_damping;
  return b;
}

std::vector<double> element_row_stiffness_n_m(const Lattice& lattice, const ElementArrays& el) {
  const std::size_t n = lattice.element_count();
  std::vector<double> k(n, 0.0);
  for_chunks(n, chunk_count(n), [&](std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t e = begin; e < end; ++e)
      if (el.inverse_mass[e] != 0) k[e] = element_rows(lattice, el, 0, e).k_max;
  });
  return k;
}

std::vector<double> relaxation_mass_scale(const Lattice& lattice, const ElementArrays& el,
                                          const std::vector<double>& extra_row_n_m) {
  return relaxation_mass_scale(el, element_row_stiffness_n_m(lattice, el), extra_row_n_m);
}

std::vector<double> relaxation_mass_scale(const ElementArrays& el, const std::vector<double>& k_row,
                                          const std::vector<double>& extra_row_n_m) {
  // An element's bound is its largest row times its inverse mass, (k + extra)/m: rounding is
  // monotone, so this is the largest of element_rows' per-row bounds to the bit.
  const std::size_t n = k_row.size();
  std::vector<double> scale(n, 1.0), omega_sq(n, 0.0);
  double highest = 0;  // of the elastic rows: the penalty makes its elements heavier, not the step shorter
  for (std::size_t e = 0; e < n; ++e) {
    if (el.inverse_mass[e] == 0) continue;
    omega_sq[e] = k_row[e] * el.inverse_mass[e];
    highest = std::max(highest, omega_sq[e]);
    if (!extra_row_n_m.empty()) omega_sq[e] = (k_row[e] + extra_row_n_m[e]) * el.inverse_mass[e];
  }
  for (std::size_t e = 0; e < n; ++e)
    if (omega_sq[e] > 0) scale[e] = highest / omega_sq[e];
  return scale;
}

double amplification(Integrator integrator, double w, double c, double dt) {
  // One step maps (x, v) → A (x, v); A's eigenvalues from its trace and determinant.
  double a11, a12, a21, a22;
  if (integrator != Integrator::Heun) {  // symplectic Euler (relaxation steps with it too)
    a21 = -dt * w * w;
    a22 = 1 - c * dt;
    a11 = 1 + dt * a21;
    a12 = dt * a22;
  } else {  // Heun = RK2 on J = [[0, 1], [−ω², −c]]: A = I + dt·J + dt²·J²/2
    const double w2 = w * w;
    a11 = 1 - 0.5 * dt * dt * w2;
    a12 = dt - 0.5 * dt * dt * c;
    a21 = -dt * w2 + 0.5 * dt * dt * c * w2;
    a22 = 1 - dt * c + 0.5 * dt * dt * (c * c - w2);
  }
  const double tr = a11 + a22, det = a11 * a22 - a12 * a21;
  const std::complex<double> root = std::sqrt(std::complex<double>(tr * tr / 4 - det, 0));
  return std::max(std::abs(tr / 2 + root), std::abs(tr / 2 - root));
}

double stable_time_step(Integrator integrator, const StabilityBounds& b, double global_damping) {
  if (b.omega_max <= 0) return INFINITY;
  const double beta = (b.damping_max - global_damping) / (b.omega_max * b.omega_max);
  auto stable = [&](double dt) {
    for (int i = 0; i <= 400; ++i) {
      // log-spaced over 6 decades below ω_max, then linear up to it
      const double s = i <= 200 ? std::pow(10.0, -6.0 + 6.0 * i / 200.0) : (i - 200) / 200.0;
      const double w = b.omega_max * s;
      if (amplification(integrator, w, global_damping + beta * w * w, dt) > 1 + 1e-12) return false;
    }
    return true;
  };
  double lo = 0, hi = 4.0 / b.omega_max;
  if (stable(hi)) return hi;
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (stable(mid) ? lo : hi) = mid;
  }
  return lo;
}

TimeStepChoice choose_time_step(const Scene& scene, const Lattice& lattice, const ElementArrays& el) {
  TimeStepChoice choice;
  const SolverSpec& s = scene.solver;
  if (s.integrator == Integrator::Relaxation) {
    // Symplectic Euler without dashpots (they do not act), every element at the bound ω_max:
    // the largest row over inverse mass, as stability_bounds(…, 0, 0) gives it.
    choice.row_stiffness_n_m = element_row_stiffness_n_m(lattice, el);
    double omega_sq = 0;
    for (std::size_t e = 0; e < lattice.element_count(); ++e)
      omega_sq = std::max(omega_sq, choice.row_stiffness_n_m[e] * el.inverse_mass[e]);
    choice.bounds.omega_max = std::sqrt(omega_sq);
    choice.stable_limit_s = stable_time_step(Integrator::SymplecticEuler, choice.bounds, 0);
  } else {
    // Triangle contact's penalty adds its stiffness to the surface elements' rows (relaxation
    // instead scales their masses, relaxation_mass_scale).
    std::vector<double> penalty;
    if (uses_triangle_contact(scene))
      penalty = triangle_contact_penalty(scene, lattice, el, build_surface(lattice)).row_n_m;
    choice.bounds = stability_bounds(lattice, el, s.dashpot_ratio, s.damping_per_s, penalty);
    choice.stable_limit_s = stable_time_step(s.integrator, choice.bounds, s.damping_per_s);
  }
  if (s.dt_s) {
    choice.dt_s = *s.dt_s;
    choice.automatic = false;
    return choice;
  }
  // Below 5% of the undamped limit the scheme is only stable through round-off: refuse.
  require(choice.stable_limit_s > 0.05 * (2.0 / choice.bounds.omega_max),
          "no stable automatic time step: Heun needs damping to be stable", "solver.dt",
          "set solver.dashpot_ratio or solver.damping > 0, use integrator = \"symplectic_euler\", or give dt");
  require(std::isfinite(choice.stable_limit_s), "no elastic connection limits the time step", "solver.dt",
          "give dt explicitly");
  choice.dt_s = s.dt_safety * choice.stable_limit_s;
  return choice;
}

}  // namespace vb
