#include "engine/sim/uniform_neighbourhood.hpp"

#include <algorithm>

namespace vb {

namespace {

bool uniform_neighbourhood(const Lattice& lattice, const std::vector<double>& E, const std::vector<double>& inverse_mass,
                           std::size_t e) {
  for (const std::int32_t j : lattice.neighbours(e))
    if (j >= 0 && (E[std::size_t(j)] != E[e] || inverse_mass[std::size_t(j)] != inverse_mass[e])) return false;
  return E[e] > 0;
}

}  // namespace

std::vector<double> mark_uniform_neighbourhoods(const Lattice& lattice, const std::vector<double>& E,
                                                const std::vector<double>& inverse_mass, std::size_t lockstep) {
  std::vector<double> marked(E);
  const std::size_t n = E.size(), block = std::max<std::size_t>(1, lockstep);
  for (std::size_t first = 0; first < n; first += block) {
    const std::size_t last = std::min(n, first + block);
    bool uniform = true;
    for (std::size_t e = first; e < last && uniform; ++e)
      if (inverse_mass[e] != 0) uniform = uniform_neighbourhood(lattice, E, inverse_mass, e);
    if (!uniform) continue;
    for (std::size_t e = first; e < last; ++e)
      if (inverse_mass[e] != 0) marked[e] = -E[e];
  }
  return marked;
}

}  // namespace vb
