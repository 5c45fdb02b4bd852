#include "engine/lattice/dual_cells.hpp"

#include <vector>

#include <Eigen/Geometry>

#include "engine/lattice/lattice.hpp"

namespace vb {

const std::array<std::uint32_t, 8>& octant_masks() {
  static const std::array<std::uint32_t, 8> masks = [] {
    std::array<std::uint32_t, 8> m{};
    const auto& offsets = neighbour_offsets();
    for (int o = 0; o < 8; ++o) {
      const int s[3] = {o & 1 ? 1 : -1, o & 2 ? 1 : -1, o & 4 ? 1 : -1};
      for (int d = 0; d < 26; ++d) {
        bool inside = true;  // every component 0 or the octant's sign
        for (int c = 0; c < 3; ++c) inside = inside && (offsets[d][c] == 0 || offsets[d][c] == s[c]);
        if (inside) m[o] |= 1u << d;
      }
    }
    return m;
  }();
  return masks;
}

double dual_volume_fraction(const std::array<std::int32_t, 26>& neighbours) {
  std::uint32_t present = 0;
  for (int d = 0; d < 26; ++d)
    if (neighbours[d] >= 0) present |= 1u << d;
  int cells = 0;
  for (const std::uint32_t m : octant_masks()) cells += (present & m) == m;
  return cells / 8.0;
}

TrilinearVolume trilinear_volume(const std::array<Eigen::Vector3d, 8>& p) {
  // x(ξ, η, ζ) = Σ_v m_v(ξ, η, ζ)·c_v with monomials 1, ξ, η, ζ, ξη, ηζ, ξζ, ξηζ and coefficient
  // vectors c_v = Σ_a coef[v][a]·p_a (corner a = i + 2j + 4k).
  static const double coef[8][8] = {
      {1, 0, 0, 0, 0, 0, 0, 0},    {-1, 1, 0, 0, 0, 0, 0, 0},   {-1, 0, 1, 0, 0, 0, 0, 0},
      {-1, 0, 0, 0, 1, 0, 0, 0},   {1, -1, -1, 1, 0, 0, 0, 0},  {1, 0, -1, 0, -1, 0, 1, 0},
      {1, -1, 0, 0, -1, 1, 0, 0},  {-1, 1, 1, -1, 1, -1, -1, 1}};
  // exponents of ξ, η, ζ in each monomial
  static const int power[8][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1},
                                  {1, 1, 0}, {0, 1, 1}, {1, 0, 1}, {1, 1, 1}};
  std::array<Eigen::Vector3d, 8> c;
  for (int v = 0; v < 8; ++v) {
    c[v].setZero();
    for (int a = 0; a < 8; ++a) c[v] += coef[v][a] * p[a];
  }
  // ∂x/∂ξ_axis = Σ_v ∂m_v/∂ξ_axis·c_v: the monomials with that exponent 1, lowered by one
  struct Term {
    int v;
    int power[3];
  };
  std::array<std::vector<Term>, 3> column;
  for (int axis = 0; axis < 3; ++axis)
    for (int v = 0; v < 8; ++v) {
      if (power[v][axis] != 1) continue;
      Term t{v, {power[v][0], power[v][1], power[v][2]}};
      t.power[axis] = 0;
      column[axis].push_back(t);
    }
  TrilinearVolume out;
  for (auto& g : out.gradient_m2) g.setZero();
  // V = ∫ det(x_ξ, x_η, x_ζ): each product of one term per column integrates to
  // det(c_u, c_v, c_w)·Π 1/(power + 1)
  for (const Term& a : column[0])
    for (const Term& b : column[1])
      for (const Term& t : column[2]) {
        if (a.v == b.v || a.v == t.v || b.v == t.v) continue;
        double weight = 1;
        for (int k = 0; k < 3; ++k) weight /= a.power[k] + b.power[k] + t.power[k] + 1;
        const Eigen::Vector3d bt = c[b.v].cross(c[t.v]), ta = c[t.v].cross(c[a.v]), ab = c[a.v].cross(c[b.v]);
        out.volume_m3 += weight * c[a.v].dot(bt);
        for (int corner = 0; corner < 8; ++corner)
          out.gradient_m2[corner] += weight * (coef[a.v][corner] * bt + coef[b.v][corner] * ta + coef[t.v][corner] * ab);
      }
  return out;
}

}  // namespace vb
