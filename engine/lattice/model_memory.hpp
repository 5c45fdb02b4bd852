#pragma once
/// The size of a model before its voxel grid is allocated: grid dimensions range-checked before
/// any cast to an integer, and an estimate of the host and device memory the model will need,
/// refused with the estimate and the finest spacing that fits.
#include <array>
#include <cstdint>
#include <string>

#include "engine/scene/scene.hpp"

namespace vb {

/// What the model may use; 0 leaves that memory unchecked.
struct MemoryBudget {
  std::uint64_t host_bytes = 0;    ///< memory available to this process (MemAvailable)
  std::uint64_t device_bytes = 0;  ///< the OpenCL device's global memory
  std::string device_name;
};

/// MemAvailable from /proc/meminfo (bytes), 0 when it cannot be read.
std::uint64_t available_host_memory_bytes();

/// A grid of voxel-centre cells, `extent_m` long on each axis, at spacing `spacing_m`: the cell
/// count per axis (at least 1), computed in double and refused (vb::Error for `key`) when it
/// is not finite or the grid has 2^31 cells or more (elements and voxels are 32-bit indices).
std::array<int, 3> grid_dims(const std::array<double, 3>& cells_per_axis, double spacing_m, const std::string& key);

/// Host bytes of a model with a grid of `voxels` cells and `elements` elements, from its label
/// grid to its outputs (per voxel: the label and the voxel → element map; per element: the
/// lattice, the element arrays, the host copies of the state and the outputs).
double estimated_host_bytes(double voxels, double elements);

/// Refuses (vb::Error on `key`) a model whose estimated host or device memory exceeds `budget`,
/// naming the estimate, what is available and the finest spacing whose model would fit.
void require_model_fits_memory(double voxels, double elements, double spacing_m, Precision precision,
                               const MemoryBudget& budget, const std::string& key);

}  // namespace vb
