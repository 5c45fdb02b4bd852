#include "engine/image/structure_set.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "engine/error.hpp"

namespace vb {
namespace {

/// Contours may reach this far (in voxels) past the outer voxel centres: half a voxel, to the
/// grid's edge, and a rounding margin.
constexpr double kEdgeMarginVoxels = 0.5 + 1e-6;
/// Points of one contour must agree on the slice to this fraction of the slice spacing.
constexpr double kPlaneToleranceSlices = 0.1;

std::string roi_where(const StructureRoi& roi) { return "ROI '" + roi.name + "'"; }

std::string mm_point(const Eigen::Vector3d& p_m) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.2f, %.2f, %.2f) mm", 1e3 * p_m.x(), 1e3 * p_m.y(), 1e3 * p_m.z());
  return text;
}

/// The contour's slice and its points in (i, j) index coordinates; throws for a malformed
/// contour or one outside the image.
int contour_slice(const std::vector<Eigen::Vector3d>& contour, std::size_t number, const StructureRoi& roi,
                  const ImageVolume& grid, const Eigen::Matrix4d& to_index, std::vector<Eigen::Vector2d>& points) {
  const std::string which = "contour " + std::to_string(number + 1);
  require(contour.size() >= 3,
          which + " has " + std::to_string(contour.size()) + " points; a closed planar contour needs at least 3",
          roi_where(roi), "check the RTSTRUCT's Contour Data");
  points.clear();
  double k_min = INFINITY, k_max = -INFINITY;
  for (const Eigen::Vector3d& p : contour) {
    // Per point: messages are built only on failure.
    if (!p.allFinite()) throw Error(which + " has a point that is not a finite number", roi_where(roi));
    const Eigen::Vector3d q = (to_index * p.homogeneous()).head<3>();
    const bool inside = q.x() >= -kEdgeMarginVoxels && q.x() <= grid.dims[0] - 1 + kEdgeMarginVoxels &&
                        q.y() >= -kEdgeMarginVoxels && q.y() <= grid.dims[1] - 1 + kEdgeMarginVoxels &&
                        q.z() >= -kEdgeMarginVoxels && q.z() <= grid.dims[2] - 1 + kEdgeMarginVoxels;
    if (!inside)
      throw Error(which + " lies outside the image: point " + mm_point(p) + " is beyond the CT's edge",
                  roi_where(roi), "the structures must be drawn on this CT");
    k_min = std::min(k_min, q.z());
    k_max = std::max(k_max, q.z());
    points.emplace_back(q.x(), q.y());
  }
  require(k_max - k_min <= kPlaneToleranceSlices,
          which + " is not in one slice plane of the CT: its points span " + std::to_string(k_max - k_min) +
              " slice spacings",
          roi_where(roi), "contours must be closed planar polygons on the CT's slices");
  return std::clamp(int(std::lround(0.5 * (k_min + k_max))), 0, grid.dims[2] - 1);
}

/// Toggles (even-odd rule) the voxels of one slice whose centres lie inside the polygon.
void toggle_inside(const std::vector<Eigen::Vector2d>& poly, const ImageVolume& grid, std::vector<std::uint8_t>& mask) {
  double y_min = INFINITY, y_max = -INFINITY;
  for (const Eigen::Vector2d& p : poly) y_min = std::min(y_min, p.y()), y_max = std::max(y_max, p.y());
  std::vector<double> crossings;
  for (int j = std::max(0, int(std::ceil(y_min))); j <= std::min(grid.dims[1] - 1, int(std::floor(y_max))); ++j) {
    crossings.clear();
    for (std::size_t e = 0; e < poly.size(); ++e) {
      const Eigen::Vector2d& a = poly[e];
      const Eigen::Vector2d& b = poly[(e + 1) % poly.size()];
      if ((a.y() <= j) != (b.y() <= j)) crossings.push_back(a.x() + (j - a.y()) * (b.x() - a.x()) / (b.y() - a.y()));
    }
    std::sort(crossings.begin(), crossings.end());
    for (std::size_t c = 0; c + 1 < crossings.size(); c += 2)
      for (int i = std::max(0, int(std::ceil(crossings[c]))); i < grid.dims[0] && i < crossings[c + 1]; ++i)
        mask[std::size_t(i) + std::size_t(grid.dims[0]) * j] ^= 1;
  }
}

}  // namespace

ImageVolume rasterise_structures(const StructureSet& set, const ImageVolume& grid, const StructureLabelRule& rule) {
  ImageVolume out;
  out.dims = grid.dims;
  out.affine_lps_m = grid.affine_lps_m;
  out.modality = "LABEL";
  out.values.assign(grid.voxel_count(), 0.f);
  std::vector<std::int32_t> owner(grid.voxel_count(), -1);  // ROI index of each labelled voxel
  const auto grid_frame = grid.dicom_tags.find("0020,0052");
  const Eigen::Matrix4d to_index = grid.affine_lps_m.inverse();
  const std::size_t slice_voxels = std::size_t(grid.dims[0]) * grid.dims[1];
  const auto rank = [&](const std::string& name) {
    return std::size_t(std::find(rule.priority.begin(), rule.priority.end(), name) - rule.priority.begin());
  };
  std::vector<Eigen::Vector2d> points;
  for (std::size_t r = 0; r < set.rois.size(); ++r) {
    const StructureRoi& roi = set.rois[r];
    if (grid_frame != grid.dicom_tags.end() && !grid_frame->second.empty() && !roi.frame_of_reference_uid.empty())
      require(roi.frame_of_reference_uid == grid_frame->second,
              "its frame of reference " + roi.frame_of_reference_uid + " is not the CT's (" + grid_frame->second + ")",
              roi_where(roi), "use the RTSTRUCT drawn on this CT series");
    const auto label = rule.labels.find(roi.name);
    require(label != rule.labels.end(), "the ROI name maps to no tissue", roi_where(roi),
            "add it to [model.structure_table] (\"ignore\" leaves it out)");
    if (label->second <= 0) continue;  // ignored
    std::map<int, std::vector<std::uint8_t>> slices;  // slice → even-odd parity of its voxels
    for (std::size_t c = 0; c < roi.contours.size(); ++c) {
      const int k = contour_slice(roi.contours[c], c, roi, grid, to_index, points);
      std::vector<std::uint8_t>& mask = slices[k];
      if (mask.empty()) mask.assign(slice_voxels, 0);
      toggle_inside(points, grid, mask);
    }
    for (const auto& [k, mask] : slices)
      for (std::size_t m = 0; m < slice_voxels; ++m) {
        if (!mask[m]) continue;
        const std::size_t v = m + slice_voxels * std::size_t(k);
        if (owner[v] >= 0) {
          const StructureRoi& other = set.rois[std::size_t(owner[v])];
          const std::size_t mine = rank(roi.name), theirs = rank(other.name);
          require(mine < rule.priority.size() && theirs < rule.priority.size(),
                  "it overlaps ROI '" + other.name + "' at voxel (" + std::to_string(m % grid.dims[0]) + ", " +
                      std::to_string(m / grid.dims[0]) + ", " + std::to_string(k) +
                      ") and no priority rule ranks the two",
                  roi_where(roi), "list both in model.structure_priority (first wins)");
          if (theirs < mine) continue;
        }
        owner[v] = std::int32_t(r);
        out.values[v] = float(label->second);
      }
  }
  return out;
}

std::vector<std::vector<Eigen::Vector3d>> contours_of_label(const ImageVolume& labels, int value) {
  std::vector<std::vector<Eigen::Vector3d>> contours;
  const int nx = labels.dims[0], ny = labels.dims[1];
  const auto in = [&](int i, int j, int k) {
    return i >= 0 && j >= 0 && i < nx && j < ny && labels.values[labels.linear_index(i, j, k)] == float(value);
  };
  // Corners of voxel edges: (i, j) is the corner at index (i − ½, j − ½).
  const auto corner_id = [&](int i, int j) { return std::int64_t(i) + std::int64_t(nx + 1) * j; };
  for (int k = 0; k < labels.dims[2]; ++k) {
    // Directed boundary edges, the label on their left: start corner → end corners.
    std::unordered_multimap<std::int64_t, std::int64_t> edges;
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        if (!in(i, j, k)) continue;
        if (!in(i, j - 1, k)) edges.emplace(corner_id(i, j), corner_id(i + 1, j));
        if (!in(i + 1, j, k)) edges.emplace(corner_id(i + 1, j), corner_id(i + 1, j + 1));
        if (!in(i, j + 1, k)) edges.emplace(corner_id(i + 1, j + 1), corner_id(i, j + 1));
        if (!in(i - 1, j, k)) edges.emplace(corner_id(i, j + 1), corner_id(i, j));
      }
    while (!edges.empty()) {
      std::vector<std::int64_t> loop;
      const std::int64_t start = edges.begin()->first;
      std::int64_t at = start;
      do {  // any outgoing edge closes a loop: the even-odd rule does not depend on the choice
        const auto edge = edges.find(at);
        loop.push_back(at);
        at = edge->second;
        edges.erase(edge);
      } while (at != start);
      std::vector<Eigen::Vector3d> contour;
      for (std::size_t n = 0; n < loop.size(); ++n) {
        const std::int64_t prev = loop[(n + loop.size() - 1) % loop.size()], here = loop[n],
                           next = loop[(n + 1) % loop.size()];
        if (next - here == here - prev) continue;  // a straight run: not a corner
        const double i = double(here % (nx + 1)) - 0.5, j = double(here / (nx + 1)) - 0.5;
        contour.push_back(labels.world_of_index(Eigen::Vector3d(i, j, k)));
      }
      contours.push_back(std::move(contour));
    }
  }
  return contours;
}

StructureSet structures_of_labels(const ImageVolume& labels, const std::map<int, std::string>& names) {
  static const std::array<std::array<int, 3>, 8> kColors = {{{255, 0, 0}, {0, 160, 255}, {255, 200, 0}, {0, 200, 80},
                                                             {200, 0, 255}, {255, 120, 0}, {0, 220, 220}, {160, 160, 160}}};
  StructureSet set;
  for (const auto& [value, name] : names) {
    StructureRoi roi;
    roi.number = value;
    roi.name = name;
    roi.color = kColors[set.rois.size() % kColors.size()];
    roi.contours = contours_of_label(labels, value);
    set.rois.push_back(std::move(roi));
  }
  return set;
}

}  // namespace vb
