#include "engine/surface/surface_elements.hpp"

#include "engine/lattice/dual_cells.hpp"

namespace vb {
namespace {

/// Bit d set when neighbour d (neighbour_offsets() order) exists.
std::uint32_t neighbour_presence(const Lattice& lattice, std::size_t e) {
  std::uint32_t present = 0;
  const auto nb = lattice.neighbours(e);
  for (int d = 0; d < 26; ++d)
    if (nb[d] >= 0) present |= 1u << d;
  return present;
}

std::uint8_t complete_octants(std::uint32_t present) {
  std::uint8_t octants = 0;
  const auto& masks = octant_masks();
  for (int o = 0; o < 8; ++o)
    if ((present & masks[o]) == masks[o]) octants |= std::uint8_t(1u << o);
  return octants;
}

bool is_surface(std::uint8_t octants) { return octants != 0 && octants != 0xFF; }

}  // namespace

std::vector<std::uint8_t> complete_octants_of_elements(const Lattice& lattice) {
  std::vector<std::uint8_t> out(lattice.element_count());
  for (std::size_t e = 0; e < out.size(); ++e) out[e] = complete_octants(neighbour_presence(lattice, e));
  return out;
}

SurfaceElements find_surface_elements(const Lattice& lattice) {
  SurfaceElements out;
  const auto& offsets = neighbour_offsets();
  for (std::size_t e = 0; e < lattice.element_count(); ++e) {
    const std::uint32_t present = neighbour_presence(lattice, e);
    if (!is_surface(complete_octants(present))) continue;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int d = 0; d < 26; ++d)
      if (!(present >> d & 1u)) sum += Eigen::Vector3d(offsets[d][0], offsets[d][1], offsets[d][2]).normalized();
    const double norm = sum.norm();
    out.element.push_back(static_cast<std::uint32_t>(e));
    // Each component is a + b/√2 + c/√3 with small integers (|a| ≤ 1, |b|, |c| ≤ 4): it is
    // exactly 0 or at least 0.025 in magnitude, so a small absolute cut is safe.
    out.outward_normal.push_back(norm > 1e-9 ? Eigen::Vector3d(lattice.rotation * (sum / norm))
                                             : Eigen::Vector3d::Zero());
  }
  return out;
}

std::size_t count_surface_elements(const Lattice& lattice) {
  std::size_t n = 0;
  for (std::size_t e = 0; e < lattice.element_count(); ++e)
    n += is_surface(complete_octants(neighbour_presence(lattice, e)));
  return n;
}

std::size_t count_complete_dual_cells(const Lattice& lattice) {
  std::size_t n = 0;  // each cell counted at its corner with the lowest coordinates (octant 7)
  for (std::size_t e = 0; e < lattice.element_count(); ++e)
    n += complete_octants(neighbour_presence(lattice, e)) >> 7;
  return n;
}

}  // namespace vb
