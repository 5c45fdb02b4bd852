#include "engine/lattice/dual_cells.hpp"

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

}  // namespace vb
