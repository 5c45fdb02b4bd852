#pragma once
/// Elements whose connections all have the same stiffness and dashpot (kernels/lattice_forces.cl,
/// lattice_force_uniform): the device's modulus array marks them with a negative sign.
#include <vector>

#include "engine/lattice/lattice.hpp"

namespace vb {

/// E (Pa) per element with the sign of a free element e negative where every present neighbour j
/// has E_j = E_e and inverse mass w_j = w_e: there a connection's k = κ_d·h·E_e and its dashpot
/// 2ζ·√(k·m_e/2) depend on its direction alone.
/// `lockstep`: elements are marked in whole aligned blocks of that many consecutive indices, all
/// free elements of a block or none (held ones never: they skip the force loop). A GPU steps
/// consecutive elements in groups of work-items that execute together (the device's simd_width),
/// and a group that holds both kinds runs both loops: on the 1.5M phantom, where tissue
/// interfaces are everywhere, marking element by element made the step 31% slower (docs/PERFORMANCE.md,
/// "Uniform-neighbourhood short loop").
std::vector<double> mark_uniform_neighbourhoods(const Lattice& lattice, const std::vector<double>& E,
                                                const std::vector<double>& inverse_mass, std::size_t lockstep = 1);

/// Whether Heun's predicted stage is stored packed by default (Simulator::pred_packed,
/// kernels/lattice_forces.cl stage_load): on GPUs, where the short loop takes at least half of the
/// `free` elements (`marked` of them). Its elements' reads of a neighbour touch 6 cache lines instead
/// of 8; the general loop's touch 11 instead of 9 (the inverse mass from the state).
inline bool default_pred_packing(bool gpu, std::size_t marked, std::size_t free) {
  return gpu && 2 * marked >= free;
}

}  // namespace vb
