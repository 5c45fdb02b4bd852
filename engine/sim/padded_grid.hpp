#pragma once
/// The kernels' padded voxel grid: the lattice's box with one empty layer on every side, so
/// neighbour lookups never leave it (kernels/common.cl). cell = (i+1) + sy·(j+1) + sz·(k+1).
#include <CL/opencl.hpp>
#include <cstddef>
#include <vector>

#include "engine/lattice/lattice.hpp"

namespace vb {

struct PaddedGrid {
  int stride_y = 0, stride_z = 0;  ///< sy, sz
  std::size_t cells = 0;           ///< padded voxels
  std::vector<cl_int> element_of_cell;  ///< cells, -1 where empty
  std::vector<cl_uint> cell_of_element;  ///< n_elements
};

/// The strides and cell count only (to check the size before the arrays are made).
PaddedGrid padded_grid_shape(const Lattice& lattice);

/// The grid with both index arrays filled.
PaddedGrid make_padded_grid(const Lattice& lattice);

}  // namespace vb
