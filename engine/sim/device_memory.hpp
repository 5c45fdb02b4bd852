#pragma once
/// What a model needs of the device's memory, and the refusals of models that do not fit, each
/// naming the need, the device and a way out (docs/PHYSICS.md §11, "Device memory").
#include <cstddef>
#include <string>

#include "engine/lattice/lattice.hpp"
#include "engine/scene/scene.hpp"
#include "engine/sim/opencl_runtime.hpp"

namespace vb {

/// Device bytes a model of `elements` elements in a padded grid of `cells` voxels needs
/// (hyperelastic models also store Q and C = FᵀF per element).
std::size_t estimated_device_bytes(std::size_t elements, std::size_t cells, Precision precision,
                                   bool hyperelastic = false);
/// Refuses (vb::Error naming the model, its need, the device and a downsample factor that would
/// fit) a model too large for `device` from its lattice alone, before the per-element arrays are
/// built: in the time the lattice takes, not the minutes and host memory the arrays would (the
/// Simulator checks again with every buffer counted).
void check_lattice_fits_device(const Scene& scene, const Lattice& lattice, const DeviceInfo& device);
/// Extra device bytes of the volume constraint (kernels/volume.cl): triangles, the per-surface-
/// element CSR of incident triangle corners, the gradient (per element) and the partial sums.
std::size_t estimated_volume_device_bytes(std::size_t elements, std::size_t surface_elements,
                                          std::size_t triangles, Precision precision);
/// Refuses a model of `device_bytes` (n elements, a padded grid of `cells`) that does not fit
/// `device`, by its total or by its largest buffer; the hint names the smallest downsample above
/// the scene's own that would fit, and float precision for a double run.
void require_fits_device(std::size_t device_bytes, std::size_t n, std::size_t cells, bool hyperelastic,
                         const Scene& scene, const DeviceInfo& device);
/// Refuses one buffer (`what`: "the model's state", ...) larger than the device allocates.
void require_buffer_fits(const std::string& what, std::size_t bytes, const DeviceInfo& device);

}  // namespace vb
