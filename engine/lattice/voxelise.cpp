#include "engine/lattice/voxelise.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "engine/error.hpp"
#include "engine/geometry/shapes.hpp"

namespace vb {

LabelVolume voxelise_shapes(const Scene& scene) {
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

  // Voxel n covers [n·h, (n+1)·h); take every voxel overlapping the bounds (the tolerance keeps
  // a bound that lies on a voxel face from adding an empty layer).
  std::array<long, 3> first{}, count{};
  for (int a = 0; a < 3; ++a) {
    first[a] = static_cast<long>(std::floor(lo[a] / h + 1e-9));
    const long last = static_cast<long>(std::ceil(hi[a] / h - 1e-9));
    count[a] = std::max(1L, last - first[a]);
  }
  const double voxels = double(count[0]) * double(count[1]) * double(count[2]);
  if (!(voxels < 4.0e9)) {
    char extent[96];
    std::snprintf(extent, sizeof extent, "%.3g × %.3g × %.3g m", count[0] * h, count[1] * h, count[2] * h);
    throw Error("the shapes span " + std::string(extent) + ", " + std::to_string(long(voxels)) + " voxels at this spacing",
                "model.spacing", "lengths are in metres; increase the spacing or shrink the shapes");
  }
  vol.dims = {int(count[0]), int(count[1]), int(count[2])};
  vol.spacing_m = h;
  vol.origin_m = Vec3((first[0] + 0.5) * h, (first[1] + 0.5) * h, (first[2] + 0.5) * h);
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
