#include "engine/sim/padded_grid.hpp"

namespace vb {

PaddedGrid padded_grid_shape(const Lattice& lattice) {
  PaddedGrid g;
  const std::size_t px = std::size_t(lattice.dims[0]) + 2, py = std::size_t(lattice.dims[1]) + 2,
                    pz = std::size_t(lattice.dims[2]) + 2;
  g.stride_y = int(px);
  g.stride_z = int(px * py);
  g.cells = px * py * pz;
  return g;
}

PaddedGrid make_padded_grid(const Lattice& lattice) {
  PaddedGrid g = padded_grid_shape(lattice);
  const std::size_t n = lattice.element_count();
  g.element_of_cell.assign(g.cells, -1);
  g.cell_of_element.resize(n);
  for (std::size_t e = 0; e < n; ++e) {
    const auto ijk = lattice.voxel_ijk(e);
    const std::size_t cell = std::size_t(ijk[0] + 1) + std::size_t(g.stride_y) * std::size_t(ijk[1] + 1) +
                             std::size_t(g.stride_z) * std::size_t(ijk[2] + 1);
    g.cell_of_element[e] = cl_uint(cell);
    g.element_of_cell[cell] = cl_int(e);
  }
  return g;
}

}  // namespace vb
