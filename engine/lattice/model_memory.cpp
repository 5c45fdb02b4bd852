#include "engine/lattice/model_memory.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "engine/error.hpp"
#include "engine/sim/device_memory.hpp"

namespace vb {
namespace {

/// Grid cells are indexed by int32 (Lattice::element_of_voxel) and uint32 (voxel_of_element).
constexpr double kMaxCells = 2147483647.0;
/// Host bytes per grid cell: the label (uint8) and the voxel → element map (int32).
constexpr double kHostBytesPerCell = 5.0;
/// Host bytes per element, measured as the peak resident memory of `voxbreast simulate` per
/// element over models of 10⁴–10⁵ elements (lattice, element arrays, neighbour tables, host
/// copies of the state, result.h5 and the per-element outputs), rounded up.
constexpr double kHostBytesPerElement = 1024.0;

std::string gib_text(double bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g GiB", bytes / double(std::uint64_t(1) << 30));
  return text;
}

}  // namespace

std::uint64_t available_host_memory_bytes() {
  std::ifstream meminfo("/proc/meminfo");
  std::string line;
  while (std::getline(meminfo, line)) {
    std::istringstream words(line);
    std::string name;
    std::uint64_t kib = 0;
    if (words >> name >> kib && name == "MemAvailable:") return kib * 1024;
  }
  return 0;
}

std::array<int, 3> grid_dims(const std::array<double, 3>& cells_per_axis, double spacing_m, const std::string& key) {
  double cells = 1.0;
  for (double n : cells_per_axis) cells = n < kMaxCells ? cells * std::max(1.0, n) : INFINITY;  // NaN too
  if (!(cells < kMaxCells)) {  // also NaN and infinity, before any cast
    char text[240];
    std::snprintf(text, sizeof text, "the model spans %.3g × %.3g × %.3g m, %.3g voxels at a spacing of %.3g m: "
                  "at most 2^31 voxels can be indexed", cells_per_axis[0] * spacing_m, cells_per_axis[1] * spacing_m,
                  cells_per_axis[2] * spacing_m, cells, spacing_m);
    throw Error(text, key, "lengths are in metres; increase the spacing or shrink or crop the model");
  }
  std::array<int, 3> dims{};
  for (int a = 0; a < 3; ++a) dims[std::size_t(a)] = int(std::max(1.0, cells_per_axis[std::size_t(a)]));
  return dims;
}

double estimated_host_bytes(double voxels, double elements) {
  return kHostBytesPerCell * voxels + kHostBytesPerElement * elements;
}

void require_model_fits_memory(double voxels, double elements, double spacing_m, Precision precision,
                               const MemoryBudget& budget, const std::string& key) {
  const double host = estimated_host_bytes(voxels, elements);
  const double device = double(estimated_device_bytes(std::size_t(elements), std::size_t(voxels), precision));
  // Memory goes with the cube of 1/spacing: the finest spacing that fits within 90% of what there
  // is, 10% coarser again for the voxels a grid's rounding up adds.
  const auto fitting_mm = [&](double need, double have) {
    return 1.1e3 * spacing_m * std::cbrt(need / (0.9 * have));
  };
  char text[320];
  if (budget.host_bytes > 0 && host > 0.9 * double(budget.host_bytes)) {
    std::snprintf(text, sizeof text, "the model needs about %s of host memory (%.3g voxels, about %.3g elements) "
                  "but %s are available", gib_text(host).c_str(), voxels, elements,
                  gib_text(double(budget.host_bytes)).c_str());
    char hint[160];
    std::snprintf(hint, sizeof hint, "a spacing of %.3g mm or more fits; or crop the model",
                  fitting_mm(host, double(budget.host_bytes)));
    throw Error(text, key, hint);
  }
  if (budget.device_bytes > 0 && device > 0.9 * double(budget.device_bytes)) {
    std::snprintf(text, sizeof text, "the model needs about %s of device memory (%.3g voxels, about %.3g elements) "
                  "but '%s' has %s", gib_text(device).c_str(), voxels, elements, budget.device_name.c_str(),
                  gib_text(double(budget.device_bytes)).c_str());
    char hint[160];
    std::snprintf(hint, sizeof hint, "a spacing of %.3g mm or more fits; or crop the model",
                  fitting_mm(device, double(budget.device_bytes)));
    throw Error(text, key, hint);
  }
}

}  // namespace vb
