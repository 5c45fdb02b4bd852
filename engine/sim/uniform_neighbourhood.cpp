#include "engine/sim/uniform_neighbourhood.hpp"

namespace vb {

std::vector<double> mark_uniform_neighbourhoods(const Lattice& lattice, const std::vector<double>& E,
                                                const std::vector<double>& inverse_mass) {
  std::vector<double> marked(E);
  for (std::size_t e = 0; e < E.size(); ++e) {
    bool uniform = E[e] > 0 && inverse_mass[e] != 0;  // held elements keep the general path
    for (const std::int32_t j : lattice.neighbours(e))
      if (j >= 0 && (E[std::size_t(j)] != E[e] || inverse_mass[std::size_t(j)] != inverse_mass[e])) uniform = false;
    if (uniform) marked[e] = -E[e];
  }
  return marked;
}

}  // namespace vb
