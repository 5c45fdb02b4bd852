#pragma once
/// Elements whose connections all have the same stiffness and dashpot (kernels/lattice_forces.cl,
/// lattice_force_uniform): the device's modulus array marks them with a negative sign.
#include <vector>

#include "engine/lattice/lattice.hpp"

namespace vb {

/// E (Pa) per element with the sign of a free element e negative where every present neighbour j
/// has E_j = E_e and inverse mass w_j = w_e: there a connection's k = κ_d·h·E_e and its dashpot
/// 2ζ·√(k·m_e/2) depend on its direction alone.
std::vector<double> mark_uniform_neighbourhoods(const Lattice& lattice, const std::vector<double>& E,
                                                const std::vector<double>& inverse_mass);

}  // namespace vb
