#pragma once
/// Observation from a label map or surface meshes of the observed posture (a second CT's segmentation, docs/FIT.md
/// "Observation from a label map"): the model's boundary faces, moved by the simulated posture
/// change, should lie on the observed boundaries of the same regions. The residual of a face is
/// its signed distance to that boundary (a distance transform of the label map, sampled
/// trilinearly): surfaces constrain only the motion normal to them.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "engine/fit/fit_data.hpp"
#include "engine/fit/signed_distance.hpp"
#include "engine/lattice/lattice.hpp"
#include "engine/scene/scene.hpp"

namespace vb {

/// One matched boundary: the observed region (voxels with one of `label_values`; none: every
/// non-zero voxel, the body) and the model faces that bound the same region (faces of tissue
/// `tissue`'s elements towards other tissue or nothing; −1: faces of the body towards air).
struct SurfaceRegion {
  std::string name;  ///< "body" or the tissue name
  std::vector<int> label_values;
  int tissue = -1;
};

/// The regions of `fit.observed_label_values` (0: the body outline; v > 0: the tissue label v
/// stands for in the model's label table, or tissue v − 1 of a shape model). Empty `values`: the
/// body and every tumour tissue of the model (names containing "tumour" or "tumor", and
/// [positioning] tumour_tissue). Throws vb::Error for a value no modelled tissue has.
/// `key` names the scene key in errors.
std::vector<SurfaceRegion> surface_regions(const Scene& scene, const Lattice& lattice, const std::vector<int>& values,
                                           const std::string& key = "fit.observed_label_values");

class SurfaceData final : public FitData {
 public:
  /// `free`: per element, whether it moves (held elements' faces are left out); `is_air`: whether
  /// an empty lattice voxel at this world point is outside the body (not bone or a crop edge).
  /// Throws vb::Error when a region has no face in the model or no boundary in the label map.
  SurfaceData(const ImageVolume& observed_labels, const Lattice& lattice, const std::vector<SurfaceRegion>& regions,
              const std::vector<bool>& free, const std::function<bool(const Eigen::Vector3d&)>& is_air, double sigma_m);
  /// The same faces against given observed surfaces, one per region (e.g. MeshSignedDistance of
  /// surface meshes, docs/FIT.md "Observation from a surface mesh"); `key` names the scene key in
  /// errors.
  SurfaceData(std::vector<std::unique_ptr<SurfaceDistance>> observed, const Lattice& lattice,
              const std::vector<SurfaceRegion>& regions, const std::vector<bool>& free,
              const std::function<bool(const Eigen::Vector3d&)>& is_air, double sigma_m, const std::string& key);

  ResidualRows rows(const std::vector<double>& change_m) const override;
  std::size_t points() const override { return points_.size(); }
  ResidualStats stats(const std::vector<double>& change_m) const override;
  const char* kind() const override { return "surface"; }

  /// signed distance (m) of every face after the posture change
  std::vector<double> distances(const std::vector<double>& change_m) const;
  /// per element: the largest |distance| of its faces (m), 0 for elements without faces
  std::vector<double> element_distance(const std::vector<double>& change_m, std::size_t elements) const;
  /// faces per region
  std::vector<std::size_t> faces_per_region() const;
  const std::vector<SurfaceRegion>& regions() const { return regions_; }

 private:
  struct Face {
    std::uint32_t element;
    std::uint32_t region;
    Eigen::Vector3d rest_m;  ///< face centre in the model's image (world, m)
  };
  std::vector<SurfaceRegion> regions_;
  void collect_faces(const Lattice& lattice, const std::vector<bool>& free,
                     const std::function<bool(const Eigen::Vector3d&)>& is_air, const std::string& key);
  std::vector<std::unique_ptr<SurfaceDistance>> fields_;
  std::vector<Face> points_;
  double weight_per_m2_;
};

}  // namespace vb
