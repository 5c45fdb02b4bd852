#include "engine/image/image_lattice.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "engine/error.hpp"

namespace vb {
namespace {

std::size_t modelled_voxels(const TissueMap& map) {
  return std::size_t(std::count_if(map.tissue.begin(), map.tissue.end(), [](std::uint8_t t) { return t != 0; }));
}

/// "air" (or any tissue named so) marks voxels that are not modelled.
bool is_air(const std::string& tissue) { return tissue == "air"; }

/// Index of `tissue` in `names` (appending it), 1-based; 0 for air.
std::uint8_t tissue_index(std::vector<std::string>& names, const std::string& tissue) {
  if (is_air(tissue)) return 0;
  auto it = std::find(names.begin(), names.end(), tissue);
  if (it == names.end()) {
    require(names.size() < 254, "too many tissues (at most 254)", "model");
    names.push_back(tissue);
    it = names.end() - 1;
  }
  return static_cast<std::uint8_t>(1 + (it - names.begin()));
}

void require_same_grid(const ImageVolume& ct, const ImageVolume& labels) {
  const bool same_dims = ct.dims == labels.dims;
  const double affine_gap = (ct.affine_lps_m - labels.affine_lps_m).cwiseAbs().maxCoeff();
  require(same_dims && affine_gap < 1e-6, "the label volume is not on the CT's voxel grid", "model.labels",
          "resample the labels onto the CT grid");
}

/// Per-voxel tissue from a label volume and the scene's label table.
std::vector<std::uint8_t> tissues_from_labels(const ModelSpec& model, const ImageVolume& labels,
                                              std::vector<std::string>& names) {
  std::map<int, std::uint8_t> index_of_label;
  for (const auto& [value, tissue] : model.label_table) index_of_label[value] = tissue_index(names, tissue);
  std::vector<std::uint8_t> out(labels.voxel_count(), 0);
  for (std::size_t v = 0; v < out.size(); ++v) {
    const auto it = index_of_label.find(static_cast<int>(std::lround(labels.values[v])));
    if (it != index_of_label.end()) out[v] = it->second;
  }
  return out;
}

/// Per-voxel tissue from HU classes: the first class containing the value wins.
std::vector<std::uint8_t> tissues_from_hu(const ModelSpec& model, const ImageVolume& ct,
                                          std::vector<std::string>& names) {
  std::vector<std::uint8_t> index_of_class;
  for (const HuClass& c : model.hu_classes) index_of_class.push_back(tissue_index(names, c.tissue));
  std::vector<std::uint8_t> out(ct.voxel_count(), 0);
  for (std::size_t v = 0; v < out.size(); ++v)
    for (std::size_t c = 0; c < model.hu_classes.size(); ++c)
      if (ct.values[v] >= model.hu_classes[c].min_hu && ct.values[v] < model.hu_classes[c].max_hu) {
        out[v] = index_of_class[c];
        break;
      }
  return out;
}

/// Renumbers tissues so only those with voxels keep a name (dropped ones then need no material).
void drop_unused_tissues(TissueMap& map) {
  std::vector<std::size_t> count(map.tissue_names.size() + 1, 0);
  for (std::uint8_t t : map.tissue) ++count[t];
  std::vector<std::uint8_t> renumber(count.size(), 0);
  std::vector<std::string> names;
  for (std::size_t t = 1; t < count.size(); ++t)
    if (count[t]) {
      names.push_back(map.tissue_names[t - 1]);
      renumber[t] = static_cast<std::uint8_t>(names.size());
    }
  for (std::uint8_t& t : map.tissue) t = renumber[t];
  map.tissue_names = std::move(names);
}

}  // namespace

TissueMap classify_image(const ModelSpec& model, const ImageVolume& ct, const ImageVolume* labels) {
  require(ct.values.size() == ct.voxel_count() && ct.voxel_count() > 0, "the CT image is empty", "model.image");
  TissueMap map;
  if (labels) {
    require_same_grid(ct, *labels);
    map.tissue = tissues_from_labels(model, *labels, map.tissue_names);
  } else {
    map.tissue = tissues_from_hu(model, ct, map.tissue_names);
  }
  // Drop tissues the scene does not keep (they then cost nothing) and voxels outside the ROI.
  for (const std::string& k : model.keep)
    require(std::find(map.tissue_names.begin(), map.tissue_names.end(), k) != map.tissue_names.end(),
            "kept tissue '" + k + "' is not produced by the label table / HU classes", "model.keep");
  std::vector<bool> kept(map.tissue_names.size() + 1, true);
  kept[0] = false;
  if (!model.keep.empty())
    for (std::size_t t = 0; t < map.tissue_names.size(); ++t)
      kept[t + 1] = std::find(model.keep.begin(), model.keep.end(), map.tissue_names[t]) != model.keep.end();
  std::size_t modelled = 0;
  for (int k = 0; k < ct.dims[2]; ++k)
    for (int j = 0; j < ct.dims[1]; ++j)
      for (int i = 0; i < ct.dims[0]; ++i) {
        std::uint8_t& t = map.tissue[ct.linear_index(i, j, k)];
        if (t && model.roi_m) {
          const Eigen::Vector3d p = ct.world_of_index(Eigen::Vector3d(i, j, k));
          const bool inside = (p.array() >= model.roi_m->first.array()).all() &&
                              (p.array() <= model.roi_m->second.array()).all();
          if (!inside) t = 0;
        }
        if (!kept[t]) t = 0;
        modelled += t != 0;
      }
  require(modelled > 0, "no CT voxel is classified as a modelled tissue", "model",
          "check the label table / HU classes, model.keep and the ROI");
  drop_unused_tissues(map);
  return map;
}

LabelVolume lattice_volume_from_image(const ModelSpec& model, const ImageVolume& ct, const TissueMap& map,
                                      Precision precision, const MemoryBudget& budget) {
  const Eigen::Matrix3d A = ct.affine_lps_m.topLeftCorner<3, 3>();
  const Eigen::Vector3d s = ct.spacing_m();
  require((s.array() > 0).all() && s.allFinite(), "the CT has a zero or invalid voxel spacing", "model.image");
  const Eigen::Matrix3d R = A * s.cwiseInverse().asDiagonal();
  require((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-4,
          "the CT's voxel axes are not perpendicular (sheared acquisition)", "model.image",
          "resample the CT onto an orthogonal grid first");
  const double h = model.spacing_m > 0 ? model.spacing_m : s.maxCoeff();

  // Bounding box of the modelled voxels, in CT indices.
  Eigen::Array3i lo(ct.dims[0], ct.dims[1], ct.dims[2]), hi(-1, -1, -1);
  for (int k = 0; k < ct.dims[2]; ++k)
    for (int j = 0; j < ct.dims[1]; ++j)
      for (int i = 0; i < ct.dims[0]; ++i)
        if (map.tissue[ct.linear_index(i, j, k)]) {
          lo = lo.min(Eigen::Array3i(i, j, k));
          hi = hi.max(Eigen::Array3i(i, j, k));
        }
  // Lattice voxel n along axis a covers [start_a + n·h, start_a + (n+1)·h) in the CT's axis
  // coordinate (metres from CT voxel 0's centre); start is the edge of the first modelled voxel.
  LabelVolume vol;
  Eigen::Vector3d start;
  std::array<double, 3> cells{};
  for (int a = 0; a < 3; ++a) {
    start[a] = (lo[a] - 0.5) * s[a];
    const double extent = (hi[a] - lo[a] + 1) * s[a];
    cells[std::size_t(a)] = std::ceil(extent / h - 1e-9);
  }
  vol.dims = grid_dims(cells, h, "model.spacing");  // range-checked before the cast
  // Elements: the modelled CT voxels' volume in lattice voxels.
  const double elements = double(modelled_voxels(map)) * s.prod() / (h * h * h);
  require_model_fits_memory(double(vol.dims[0]) * vol.dims[1] * vol.dims[2], std::max(1.0, elements), h, precision,
                            budget, "model.spacing");
  vol.spacing_m = h;
  vol.rotation = R;
  vol.origin_m = ct.world_of_index(Eigen::Vector3d::Zero()) + R * (start + Eigen::Vector3d::Constant(0.5 * h));
  vol.tissue_names = map.tissue_names;
  vol.labels.assign(std::size_t(vol.dims[0]) * vol.dims[1] * vol.dims[2], 0);
  for (int k = 0; k < vol.dims[2]; ++k)
    for (int j = 0; j < vol.dims[1]; ++j)
      for (int i = 0; i < vol.dims[0]; ++i) {
        const Eigen::Vector3d axis_m = start + h * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5);
        const Eigen::Vector3d index = axis_m.cwiseQuotient(s);
        const int ci = int(std::lround(index[0])), cj = int(std::lround(index[1])), ck = int(std::lround(index[2]));
        if (ci < 0 || cj < 0 || ck < 0 || ci >= ct.dims[0] || cj >= ct.dims[1] || ck >= ct.dims[2]) continue;
        vol.labels[vol.linear_index(i, j, k)] = map.tissue[ct.linear_index(ci, cj, ck)];
      }
  return vol;
}

}  // namespace vb
