#pragma once
/// What `voxbreast fit` estimates and from what: the [fit] table of a scene file (docs/FIT.md).
/// SI units inside; the file gives lengths in mm with the unit in the key name.
#include <optional>
#include <string>
#include <vector>

#include "engine/scene/scene.hpp"

namespace vb {

struct FitSpec {
  /// Gravity of the posture the model's image was taken in (world, m/s²); empty: none (the
  /// image geometry is unloaded). The scene's [gravity] is the observed posture's.
  std::optional<Vec3> from_gravity_m_s2;
  std::string from_posture;  ///< name when given by posture ("" otherwise)

  // Observation: element displacements from the `from` to the scene's posture.
  std::string dvf_path;        ///< NIfTI displacement field on any grid (sampled at element centres)
  std::string landmarks_path;  ///< CSV: x_mm,y_mm,z_mm,dx_mm,dy_mm,dz_mm[,sigma_mm] (LPS)
  /// a label map of the observed posture (any grid): its boundaries are matched instead of displacements
  std::string observed_labels_path;
  /// which boundaries count: 0 the body outline, v > 0 the region of label v (empty: body + tumours)
  std::vector<int> observed_label_values;
  /// surface meshes (STL, mm, LPS) of boundaries in the observed posture, matched like a label map's
  std::vector<std::string> observed_surface_paths;
  /// which boundary each surface is: 0 the body outline, v > 0 the region of label v (one file: {0})
  std::vector<int> observed_surface_values;
  std::string mask_path;       ///< NIfTI: elements where it is 0 are not observed
  std::string sigma_path;      ///< NIfTI: per-point displacement uncertainty (mm)
  double sigma_m = 0.001;      ///< uncertainty of an observed displacement component (m)

  // Unknowns
  enum class Regions { Labels, Blocks, Elements };
  Regions regions = Regions::Labels;
  double block_m = 0.02;             ///< blocks: cube edge (m)
  std::vector<std::string> tissues;  ///< fitted tissues (empty: every non-rigid tissue)
  double min_modulus_pa = 0;         ///< bounds; 0: from the material table (docs/FIT.md)
  double max_modulus_pa = 0;
  enum class Initial { Materials, Hu };
  Initial initial = Initial::Hu;  ///< Hu needs a CT image model; else the material table

  // Method
  enum class Method { GaussNewton, Bisection };
  Method method = Method::GaussNewton;
  int max_iterations = 20;
  double regularisation = 1e-6;  ///< Tikhonov weight α on Σ (ln E − ln E_initial)² (docs/FIT.md)
  double step_log = 0.05;        ///< finite-difference step of the Jacobian in log E
  double tolerance = 1e-4;       ///< stop when the cost falls by less than this fraction
  /// forward solves' residual tolerance (overrides stop.equilibrium); 0: 1e-7 in double
  /// precision, 1e-5 in float (whose rounding floor lies near 1e-6)
  double equilibrium = 0;
  std::int64_t max_steps = 50000;  ///< per forward solve and posture
  /// model copies one simulator relaxes together for the Jacobian's perturbed solves (docs/FIT.md,
  /// "Batched solves"); 0 (auto): one at a time, as 1 (batches lost on PoCL and an H200); N: N copies
  int batch = 0;

  /// solve from the unloaded reference state ([reference_state]): rest offsets re-estimated per
  /// forward solve with the trial moduli. Unset: on exactly when the scene has [reference_state].
  std::optional<bool> unloaded_reference;

  int line = 0;
};

}  // namespace vb
