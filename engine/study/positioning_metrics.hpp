#pragma once
/// What a positioning study asks of one run (docs/POSITIONING.md): where the tumour went, how far
/// the breast stands off the chest wall, how hard the device pushes, and how strained the tissue
/// is. Host-side, from the final state; SI units, world frame.
#include <optional>
#include <string>

#include "engine/lattice/lattice.hpp"
#include "engine/scene/scene.hpp"
#include "engine/sim/element_setup.hpp"
#include "engine/sim/run_result.hpp"
#include "engine/study/reproducibility.hpp"

namespace vb {

/// Mass-weighted centroid of the elements of one tissue, at rest and at the end.
struct TumourMetrics {
  std::string tissue;
  std::size_t elements = 0;
  Vec3 rest_centroid_m = Vec3::Zero(), final_centroid_m = Vec3::Zero();
  Vec3 displacement_m() const { return final_centroid_m - rest_centroid_m; }
  std::optional<Vec3> target_m;  ///< [positioning] target
  double rest_target_distance_m = 0, final_target_distance_m = 0;  ///< |centroid − target| (m)
};

/// Distances from the chest-wall anchor's surface (sphere: |x − c| − r; halfspace: the distance
/// to its plane on the free side), positive away from the chest wall. The sphere's pose does not
/// move its surface (a rotation about its centre).
struct ChestWallMetrics {
  std::string anchor;
  std::optional<double> tumour_rest_m, tumour_final_m;  ///< of the tumour centroid (when there is one)
  double mean_rest_m = 0, mean_final_m = 0;  ///< mass-weighted mean over the free elements: the lift
  double max_rest_m = 0, max_final_m = 0;    ///< farthest free element: how far the breast stands out
};

/// Comfort proxies over the elements of soft (non-rigid) tissue.
struct ComfortMetrics {
  double peak_equivalent_strain = 0, p95_equivalent_strain = 0;
  double peak_von_mises_pa = 0, p95_von_mises_pa = 0;
};

/// The unloaded reference state's estimate ([reference_state]).
struct ReferenceStateMetrics {
  int iterations = 0;
  bool converged = false;
  double residual_max_m = 0, residual_rms_m = 0;  ///< how far the loaded estimate lands from the CT
  double max_rest_offset_m = 0;                   ///< largest |u0|: unloaded shape vs CT
};

struct PositioningMetrics {
  std::optional<TumourMetrics> tumour;         ///< absent without a tumour tissue
  std::optional<ChestWallMetrics> chest_wall;  ///< absent without a chest-wall anchor
  ComfortMetrics comfort;
  double volume_change = 0, surface_volume_change = 0;  ///< fractions (RunSummary)
  std::optional<ReferenceStateMetrics> reference_state;   ///< scenes with [reference_state]
  std::optional<ReproducibilityResult> reproducibility;   ///< scenes with [reproducibility]
};

/// The tissue is [positioning] tumour_tissue, else "tumour" when the model has it; the chest wall
/// is [positioning] chest_wall, else the scene's only sphere anchor. Throws vb::Error when
/// tumour_tissue names a tissue the model lacks.
PositioningMetrics compute_positioning_metrics(const Scene& scene, const Lattice& lattice, const ElementArrays& elements,
                                               const RunSummary& summary, const FinalState& state);

/// Throws the error compute_positioning_metrics would (a named tumour tissue the model lacks), so
/// a run can fail before it starts rather than after.
void check_positioning(const Scene& scene, const Lattice& lattice);

/// The chest-wall anchor: [positioning] chest_wall, else the scene's only sphere anchor; nullptr
/// when there is none (or several spheres and none named).
const AnchorSpec* chest_wall_anchor(const Scene& scene);

/// Signed distance of x from the anchor's surface (m), positive outside the held region; sphere
/// and halfspace anchors only.
double distance_from_anchor_m(const AnchorSpec& anchor, const Vec3& x_m);

}  // namespace vb
