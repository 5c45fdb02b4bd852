#include "engine/sim/device_memory.hpp"

#include <algorithm>
#include <cmath>

#include "engine/error.hpp"
#include "engine/sim/element_setup.hpp"
#include "engine/sim/kernel_arg_layout.hpp"
#include "engine/sim/padded_grid.hpp"

namespace vb {
namespace {

std::string mib(double bytes) { return std::to_string(static_cast<long long>(bytes / (1 << 20))) + " MiB"; }

/// Smallest downsample factor f above the scene's own, d, whose model (about bytes·(d/f)³) fits
/// the device.
int fitting_downsample(std::size_t bytes, int d, const DeviceInfo& device) {
  const double budget = 0.9 * double(device.global_memory_bytes);
  int f = d + 1;
  while (double(bytes) * std::pow(double(d) / f, 3) > budget && f < 64) ++f;
  return f;
}

}  // namespace

/// Refuses a model of `device_bytes` (n elements, a padded grid of `cells`) that does not fit
/// `device`: its largest buffers are the state arena (3 state vectors' worth with the stress
/// rows of hyperelastic tissue) and the grid.
void require_fits_device(std::size_t device_bytes, std::size_t n, std::size_t cells, bool hyperelastic,
                         const Scene& scene, const DeviceInfo& device) {
  const std::size_t state_bytes = 4 * (scene.solver.precision == Precision::Double ? 8 : 4) * n;
  const std::size_t largest_buffer_bytes = std::max((hyperelastic ? 3 : 1) * state_bytes, cells * sizeof(cl_int));
  require(double(device_bytes) < 0.9 * double(device.global_memory_bytes) &&
              largest_buffer_bytes <= device.max_allocation_bytes,
          "the model needs " + mib(double(device_bytes)) + " of device memory but '" + device.name + "' has " +
              mib(double(device.global_memory_bytes)) + " (largest buffer " +
              mib(double(device.max_allocation_bytes)) + ")",
          "model",
          "set model.downsample to at least " +
              std::to_string(fitting_downsample(device_bytes, scene.model.downsample, device)) +
              ", crop the model (model.roi_min/max, model.keep)" +
              (scene.solver.precision == Precision::Double ? ", or use float precision" : ""));
}

void require_buffer_fits(const std::string& what, std::size_t bytes, const DeviceInfo& device) {
  require(bytes <= device.max_allocation_bytes,
          what + " needs one buffer of " + mib(double(bytes)) + " but '" + device.name + "' allocates at most " +
              mib(double(device.max_allocation_bytes)),
          "model", "downsample or crop the model");
}

void check_lattice_fits_device(const Scene& scene, const Lattice& lattice, const DeviceInfo& device) {
  const bool hyperelastic = has_hyperelastic_tissue(scene, lattice);
  const std::size_t n = lattice.element_count();
  const std::size_t cells = padded_grid_shape(lattice).cells;
  require_fits_device(estimated_device_bytes(n, cells, scene.solver.precision, hyperelastic), n, cells, hyperelastic,
                      scene, device);
}

std::size_t estimated_device_bytes(std::size_t elements, std::size_t cells, Precision precision, bool hyperelastic) {
  const std::size_t real = precision == Precision::Double ? 8 : 4;
  const std::size_t hyper = hyperelastic ? 4 * 4 * real + 1 : 0;  // Q rows and C (hyper_store), tissue id
  return elements * (4 * 4 * real + real + 4 + hyper) + cells * 4;
}

std::size_t estimated_volume_device_bytes(std::size_t elements, std::size_t surface_elements, std::size_t triangles,
                                          Precision precision) {
  const std::size_t real = precision == Precision::Double ? 8 : 4;
  const std::size_t groups = (surface_elements + kCheckWorkGroup - 1) / kCheckWorkGroup;  // one item per surface element
  return triangles * 3 * 4                       // triangle corners (element ids)
         + surface_elements * 4 + (surface_elements + 1) * 4 + triangles * 3 * 8  // CSR of incident corners (pairs)
         + elements * 4 * real                   // gradient per element
         + (groups * kVolumeSlots + kVolumeScalars) * real;
}

}  // namespace vb
