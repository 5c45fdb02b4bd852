#pragma once
/// What a run produces, handed from the simulator to the writers (io/). SI units throughout.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace vb {

struct TrackedPointResult {
  std::string name;
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();        ///< requested world point (m)
  Eigen::Vector3d rest_m = Eigen::Vector3d::Zero();         ///< rest position of the tracked element (m)
  Eigen::Vector3d displacement_m = Eigen::Vector3d::Zero(); ///< final displacement (m)
  std::int64_t element = -1;                                ///< nearest element
};

struct IndenterResult {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();     ///< final sphere centre / plate point (m)
  Eigen::Vector3d reaction_force_n = Eigen::Vector3d::Zero();  ///< force the tissue exerts on it (N)
  std::int64_t contact_elements = 0;
  /// reaction force history at each check: (time s, fx, fy, fz N, indenter displacement m)
  std::vector<std::array<double, 5>> history;
};

/// One torus of the immobilisation device at the end of the run ([[device.torus]]).
struct TorusResult {
  std::string name;
  double minor_radius_m = 0, major_radius_m = 0;  ///< at the final time
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();  ///< force the tissue exerts on it (N)
  std::int64_t contact_elements = 0;
  double contact_area_m2 = 0;     ///< surface-area shares of the contact elements
  double normal_force_sum_n = 0;  ///< Σ |normal force| over the contact elements (N): the squeeze
  double peak_pressure_pa = 0;    ///< largest element normal force over its area share
  double mean_pressure_pa = 0;    ///< total normal force over the contact area
  double max_penetration_m = 0;   ///< deepest free element inside the tube, final state
  double max_penetration_run_m = 0;  ///< the same, largest over every check of the run
};

struct RunSummary {
  std::size_t elements = 0;
  std::size_t connections = 0;
  std::size_t fixed_elements = 0;
  std::int64_t steps = 0;
  double dt_s = 0;
  bool dt_auto = true;
  double simulated_time_s = 0;
  double wall_time_s = 0;
  double steps_per_second = 0;
  bool converged = false;
  std::string stop_reason;          ///< "equilibrium", "max_steps", "max_time"
  /// Why a run that was to reach equilibrium (stop.equilibrium > 0) has no converged result: it
  /// stopped at max_steps or time, or met the test only trivially (the load itself below the
  /// tolerance). Empty when converged, or when the equilibrium test was off (a run of a fixed
  /// number of steps or time, as asked).
  std::string unconverged_reason;
  double final_residual = 0;        ///< max residual force / reference force (dimensionless)
  double final_speed_ratio = 0;     ///< max speed / elastic wave speed (dimensionless)
  double max_displacement_m = 0;
  double volume_change = 0;         ///< (V - V0)/V0 from per-element det F (fraction)
  /// (V − V0)/V0 of the volume enclosed by the surface mesh (docs/SURFACE.md; fraction); 0 when
  /// the model has no closed surface. What [volume] preserve holds.
  double surface_volume_change = 0;
  std::string device_name;
  std::string precision;            ///< "float" | "double"
  std::string integrator;           ///< "symplectic_euler" | "heun"
  std::vector<TrackedPointResult> tracked;
  std::vector<IndenterResult> indenters;
  std::vector<TorusResult> tori;
};

/// Final per-element state (n = element count; vectors are n×3 row-major).
struct FinalState {
  std::vector<double> position_m;        ///< n×3 (m)
  std::vector<double> displacement_m;    ///< n×3 (m)
  std::vector<double> velocity_m_s;      ///< n×3 (m/s)
  std::vector<double> volumetric_strain; ///< n, det F − 1
  std::vector<double> equivalent_strain; ///< n, von Mises equivalent of Green-Lagrange strain
  std::vector<double> von_mises_stress_pa;  ///< n, small-strain linear-lattice stress (Pa)
  /// n×3 (m): the unloaded reference state as offsets from the voxel centres ([reference_state]);
  /// empty without one
  std::vector<double> rest_offset_m;
};

/// Optional displacement frames (every `frames_every` steps).
struct Frames {
  std::vector<double> time_s;
  std::vector<std::vector<float>> displacement_m;  ///< per frame, n×3 (m)
};

}  // namespace vb
