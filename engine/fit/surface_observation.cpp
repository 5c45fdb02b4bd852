#include "engine/fit/surface_observation.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "engine/error.hpp"

namespace vb {
namespace {

bool is_tumour_name(const std::string& name, const Scene& scene) {
  return name.find("tumour") != std::string::npos || name.find("tumor") != std::string::npos ||
         (!scene.positioning.tumour_tissue.empty() && name == scene.positioning.tumour_tissue);
}

}  // namespace

std::vector<SurfaceRegion> surface_regions(const Scene& scene, const Lattice& lattice, const std::vector<int>& values,
                                           const std::string& key) {
  // label values of each modelled tissue
  std::vector<std::vector<int>> values_of(lattice.tissue_names.size());
  for (std::size_t t = 0; t < lattice.tissue_names.size(); ++t) {
    if (scene.model.label_table.empty()) values_of[t].push_back(int(t) + 1);
    for (const auto& [v, name] : scene.model.label_table)
      if (name == lattice.tissue_names[t]) values_of[t].push_back(v);
  }
  std::vector<int> tissues;  // chosen, in order, without repeats; −1: the body
  if (values.empty()) {
    tissues.push_back(-1);
    for (std::size_t t = 0; t < lattice.tissue_names.size(); ++t)
      if (is_tumour_name(lattice.tissue_names[t], scene)) tissues.push_back(int(t));
  } else {
    for (const int v : values) {
      int t = -1;
      if (v != 0) {
        for (std::size_t u = 0; u < values_of.size() && t < 0; ++u)
          if (std::find(values_of[u].begin(), values_of[u].end(), v) != values_of[u].end()) t = int(u);
        require(t >= 0, "label value " + std::to_string(v) + " is no tissue of the model", key,
                "use 0 for the body outline, else a label value of a modelled tissue ([model.label_table], keep)");
      }
      if (std::find(tissues.begin(), tissues.end(), t) == tissues.end()) tissues.push_back(t);
    }
  }
  std::vector<SurfaceRegion> out;
  for (const int t : tissues)
    out.push_back(t < 0 ? SurfaceRegion{"body", {}, -1}
                        : SurfaceRegion{lattice.tissue_names[std::size_t(t)], values_of[std::size_t(t)], t});
  return out;
}

SurfaceData::SurfaceData(const ImageVolume& observed, const Lattice& lattice, const std::vector<SurfaceRegion>& regions,
                         const std::vector<bool>& free, const std::function<bool(const Eigen::Vector3d&)>& is_air,
                         double sigma_m)
    : regions_(regions), weight_per_m2_(1 / (sigma_m * sigma_m)) {
  for (const SurfaceRegion& region : regions_) {
    std::vector<std::uint8_t> inside(observed.voxel_count());
    for (std::size_t i = 0; i < inside.size(); ++i) {
      const int v = int(std::lround(observed.values[i]));
      inside[i] = region.label_values.empty()
                      ? v != 0
                      : std::find(region.label_values.begin(), region.label_values.end(), v) != region.label_values.end();
    }
    fields_.push_back(std::make_unique<SignedDistanceField>(observed, inside, "fit.observed_labels, region " + region.name));
  }
  collect_faces(lattice, free, is_air, "fit.observed_label_values");
}

SurfaceData::SurfaceData(std::vector<std::unique_ptr<SurfaceDistance>> observed, const Lattice& lattice,
                         const std::vector<SurfaceRegion>& regions, const std::vector<bool>& free,
                         const std::function<bool(const Eigen::Vector3d&)>& is_air, double sigma_m, const std::string& key)
    : regions_(regions), fields_(std::move(observed)), weight_per_m2_(1 / (sigma_m * sigma_m)) {
  require(fields_.size() == regions_.size(), "one observed surface per region is needed", key);
  collect_faces(lattice, free, is_air, key);
}

void SurfaceData::collect_faces(const Lattice& lattice, const std::vector<bool>& free,
                                const std::function<bool(const Eigen::Vector3d&)>& is_air, const std::string& key) {
  const Eigen::Matrix4d A = lattice.affine();
  for (std::size_t r = 0; r < regions_.size(); ++r) {
    const SurfaceRegion& region = regions_[r];
    // the model's faces of this region: free elements with a face neighbour outside it
    std::size_t faces = 0;
    for (std::size_t e = 0; e < lattice.element_count(); ++e) {
      if (!free[e]) continue;
      if (region.tissue >= 0 && lattice.tissue_of_element[e] != region.tissue) continue;
      const auto ijk = lattice.voxel_ijk(e);
      const auto nb = lattice.neighbours(e);
      for (int d = 0; d < 6; ++d) {  // the 6 face neighbours come first
        const auto& o = neighbour_offsets()[std::size_t(d)];
        const Eigen::Vector3d centre(ijk[0] + 0.5 * o[0], ijk[1] + 0.5 * o[1], ijk[2] + 0.5 * o[2]);
        const Eigen::Vector3d face = (A * centre.homogeneous()).head<3>();
        bool boundary;
        if (region.tissue < 0) {
          const Eigen::Vector3d beyond(ijk[0] + o[0], ijk[1] + o[1], ijk[2] + o[2]);
          boundary = nb[std::size_t(d)] < 0 && is_air((A * beyond.homogeneous()).head<3>());
        } else {
          boundary = nb[std::size_t(d)] < 0 || lattice.tissue_of_element[std::size_t(nb[std::size_t(d)])] != region.tissue;
        }
        if (!boundary) continue;
        points_.push_back(Face{std::uint32_t(e), std::uint32_t(r), face});
        ++faces;
      }
    }
    require(faces > 0, "the model has no free boundary face of region " + region.name, key,
            "choose regions whose boundary moves (not held by anchors or rigid tissue)");
  }
}

std::vector<double> SurfaceData::distances(const std::vector<double>& change_m) const {
  std::vector<double> d(points_.size());
  for (std::size_t k = 0; k < points_.size(); ++k) {
    const Face& f = points_[k];
    const std::size_t e = f.element;
    const Eigen::Vector3d moved = f.rest_m + Eigen::Vector3d(change_m[3 * e], change_m[3 * e + 1], change_m[3 * e + 2]);
    d[k] = fields_[f.region]->at(moved);
  }
  return d;
}

ResidualRows SurfaceData::rows(const std::vector<double>& change_m) const {
  const std::vector<double> d = distances(change_m);
  ResidualRows r;
  r.value_m = Eigen::Map<const Eigen::VectorXd>(d.data(), Eigen::Index(d.size()));
  r.weight_per_m2 = Eigen::VectorXd::Constant(Eigen::Index(d.size()), weight_per_m2_);
  return r;
}

ResidualStats SurfaceData::stats(const std::vector<double>& change_m) const {
  std::vector<double> d = distances(change_m);
  for (double& x : d) x = std::abs(x);
  return distance_stats(std::move(d));
}

std::vector<double> SurfaceData::element_distance(const std::vector<double>& change_m, std::size_t elements) const {
  const std::vector<double> d = distances(change_m);
  std::vector<double> out(elements, 0.0);
  for (std::size_t k = 0; k < points_.size(); ++k)
    out[points_[k].element] = std::max(out[points_[k].element], std::abs(d[k]));
  return out;
}

std::vector<std::size_t> SurfaceData::faces_per_region() const {
  std::vector<std::size_t> n(regions_.size(), 0);
  for (const Face& f : points_) ++n[f.region];
  return n;
}

}  // namespace vb
