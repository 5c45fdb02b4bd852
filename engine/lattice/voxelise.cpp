#include "engine/lattice/voxelise.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "engine/error.hpp"
#include "engine/geometry/shapes.hpp"
#include "engine/lattice/model_memory.hpp"

namespace vb {
namespace {

/// Largest distance of a shape coordinate from the origin (m).
constexpr double kMaxCoordinateM = 100.0;

}  // namespace

LabelVolume voxelise_shapes(const Scene& scene, const MemoryBudget& budget) {
  const ModelSpec& model = scene.model;
  require(model.spacing_m > 0 && std::isfinite(model.spacing_m), "spacing must be positive",
          "model.spacing");
  require(!model.shapes.empty(), "the model has no shapes", "model");
  const double h = model.spacing_m;

  Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
  LabelVolume vol;
  for (const ShapeSpec& s : model.shapes) {
    auto [a, b] = shape_bounds(s);
    lo = lo.cwiseMin(a);
    hi = hi.cwiseMax(b);
    if (std::find(vol.tissue_names.begin(), vol.tissue_names.end(), s.label) == vol.tissue_names.end())
      vol.tissue_names.push_back(s.label);
  }
  require(vol.tissue_names.size() < 255, "too many tissue labels (at most 254)", "model.shape");

  // Coordinates are range-checked before they are divided and cast: beyond 100 m from the origin a
  // shape is a unit mistake, and its voxel indices would not fit an integer.
  const double reach = std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff());
  if (!(reach <= kMaxCoordinateM)) {
    char text[120];
    std::snprintf(text, sizeof text, "the shapes reach %.3g m from the origin (at most %g m)", reach, kMaxCoordinateM);
    throw Error(text, "model.shape", "coordinates and lengths are in metres");
  }
  // Voxel n covers [n·h, (n+1)·h); take every voxel overlapping the bounds (the tolerance keeps
  // a bound that lies on a voxel face from adding an empty layer).
  std::array<double, 3> first{}, count{};
  for (int a = 0; a < 3; ++a) {
    first[std::size_t(a)] = std::floor(lo[a] / h + 1e-9);
    count[std::size_t(a)] = std::max(1.0, std::ceil(hi[a] / h - 1e-9) - first[std::size_t(a)]);
  }
  vol.dims = grid_dims(count, h, "model.spacing");
  const double voxels = double(vol.dims[0]) * double(vol.dims[1]) * double(vol.dims[2]);
  vol.origin_m = Vec3((first[0] + 0.5) * h, (first[1] + 0.5) * h, (first[2] + 0.5) * h);
  // The occupied fraction, sampled on at most 32³ voxel centres, estimates the elements before
  // the grid is allocated.
  std::array<int, 3> samples{};
  for (int a = 0; a < 3; ++a) samples[std::size_t(a)] = std::min(vol.dims[std::size_t(a)], 32);
  std::size_t inside = 0;
  for (int k = 0; k < samples[2]; ++k)
    for (int j = 0; j < samples[1]; ++j)
      for (int i = 0; i < samples[0]; ++i) {
        const Vec3 index((i + 0.5) * vol.dims[0] / samples[0], (j + 0.5) * vol.dims[1] / samples[1],
                         (k + 0.5) * vol.dims[2] / samples[2]);
        const Vec3 p = vol.origin_m + h * index.array().floor().matrix();
        inside += std::any_of(model.shapes.begin(), model.shapes.end(),
                              [&](const ShapeSpec& shape) { return shape_contains(shape, p); });
      }
  const double fraction = double(inside) / (double(samples[0]) * samples[1] * samples[2]);
  require_model_fits_memory(voxels, std::max(1.0, fraction * voxels), h, scene.solver.precision, budget,
                            "model.spacing");
  vol.spacing_m = h;
  vol.labels.assign(std::size_t(vol.dims[0]) * vol.dims[1] * vol.dims[2], 0);

  std::vector<std::uint8_t> label_of_shape;
  for (const ShapeSpec& s : model.shapes) {
    auto it = std::find(vol.tissue_names.begin(), vol.tissue_names.end(), s.label);
    label_of_shape.push_back(static_cast<std::uint8_t>(1 + (it - vol.tissue_names.begin())));
  }
  for (int k = 0; k < vol.dims[2]; ++k)
    for (int j = 0; j < vol.dims[1]; ++j)
      for (int i = 0; i < vol.dims[0]; ++i) {
        const Vec3 p = vol.origin_m + h * Vec3(i, j, k);
        std::uint8_t label = 0;
        for (std::size_t s = 0; s < model.shapes.size(); ++s)
          if (shape_contains(model.shapes[s], p)) label = label_of_shape[s];
        vol.labels[vol.linear_index(i, j, k)] = label;
      }
  return vol;
}

}  // namespace vb
