#pragma once
/// OpenCL source of the lattice tables, generated from the host's definitions so kernels and
/// host reference can never disagree on directions or stiffness coefficients.
#include <string>

namespace vb {

/// `__constant` arrays VB_DIR, VB_DIR_LEN, VB_KAPPA, VB_OCTANT_MASK (dual cells) typed with `real` (so it must follow common.cl).
std::string lattice_tables_source();

}  // namespace vb
