#include "engine/sim/uniform_neighbourhood.hpp"

#include "engine/lattice/lattice.hpp"

namespace vb {

std::vector<double> mark_uniform_neighbourhoods(const std::vector<double>& E, const std::vector<double>& inverse_mass,
                                                const std::vector<std::int32_t>& grid,
                                                const std::vector<std::uint32_t>& cell_of, int sy, int sz) {
  std::vector<double> marked(E);
  for (std::size_t e = 0; e < E.size(); ++e) {
    bool uniform = E[e] > 0 && inverse_mass[e] != 0;  // held elements keep the general path
    for (const auto& d : neighbour_offsets()) {
      const std::int32_t j = grid[std::int64_t(cell_of[e]) + d[0] + std::int64_t(sy) * d[1] + std::int64_t(sz) * d[2]];
      if (j >= 0 && (E[std::size_t(j)] != E[e] || inverse_mass[std::size_t(j)] != inverse_mass[e])) uniform = false;
    }
    if (uniform) marked[e] = -E[e];
  }
  return marked;
}

}  // namespace vb
