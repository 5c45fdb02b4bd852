#pragma once
/// What the fit's cost compares a forward solution with (docs/FIT.md, "Cost"): residual rows with
/// their weights, whatever the kind of observation — element displacements (DVF, landmarks) or
/// surfaces (a label map of the observed posture). The solvers see only this.
#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "engine/fit/observation.hpp"

namespace vb {

struct ResidualRows {
  Eigen::VectorXd value_m;        ///< simulated − observed, one row per scalar residual (m)
  Eigen::VectorXd weight_per_m2;  ///< 1/σ² of each row
};

class FitData {
 public:
  virtual ~FitData() = default;
  /// residual rows of the posture change `change_m` (n×3, m, per element)
  virtual ResidualRows rows(const std::vector<double>& change_m) const = 0;
  /// the cost's normaliser N: observed points (elements, or surface points)
  virtual std::size_t points() const = 0;
  /// per observed point: |residual| statistics (displacement error or surface distance)
  virtual ResidualStats stats(const std::vector<double>& change_m) const = 0;
  /// "displacement" or "surface"
  virtual const char* kind() const = 0;
};

/// Displacement matching: 3 rows (x, y, z) per observed element of the observation.
class DisplacementData final : public FitData {
 public:
  explicit DisplacementData(const Observation& obs) : obs_(obs) {}
  ResidualRows rows(const std::vector<double>& change_m) const override;
  std::size_t points() const override { return obs_.observed_elements(); }
  ResidualStats stats(const std::vector<double>& change_m) const override { return residual_stats(obs_, change_m); }
  const char* kind() const override { return "displacement"; }

 private:
  const Observation& obs_;
};

}  // namespace vb
