#pragma once
/// A sphere probe for haptic rendering (docs/HAPTICS.md): the deformation is updated on the
/// OpenCL device in a thread of its own, as fast as it goes, while force() answers at any rate
/// from the last update and a local linearisation, F(x) = F_last + K·(x − x_last), with K the
/// contact stiffness estimated from the updates: Broyden's secant update over the probe's last
/// move, refreshed at every update while the force settles (so a held probe's K becomes the
/// secant of equilibrium forces), kept symmetric and negative semi-definite (the tissue pushes
/// back harder the deeper the probe goes).
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "engine/results/element_measures.hpp"
#include "engine/sim/simulator.hpp"

namespace vb {

struct HapticOptions {
  std::size_t probe = 0;            ///< the scene's indenter that is the probe (a sphere)
  int steps_per_update = 0;         ///< time steps between force readings; 0: solver.check_every
  double max_move_per_update = 0.25;  ///< largest probe move per update, in lattice spacings
  /// The fold monitor (docs/HAPTICS.md, "Folding"): the deformation thread checks det F of the
  /// free elements once the probe has moved this many spacings since the last check ...
  double fold_check_move = 0.5;
  /// ... and at least this often (s, wall clock) while it holds still: folding can develop while
  /// the tissue relaxes under a held probe.
  double fold_check_every_s = 0.25;
};

/// The probe's state after one deformation update.
struct HapticUpdate {
  std::int64_t count = 0;                ///< updates so far
  Vec3 probe_m = Vec3::Zero();           ///< where the simulated probe is (m, world)
  Vec3 force_n = Vec3::Zero();           ///< force the tissue exerts on it (N, world)
  Eigen::Matrix3d stiffness_n_m = Eigen::Matrix3d::Zero();  ///< K = ∂F/∂x estimate (N/m)
  std::int64_t contact_elements = 0;
  double residual = 0;                   ///< max residual force / F_ref (docs/SCENE.md)
  std::int64_t steps = 0;                ///< time steps so far
  bool blown_up = false;                 ///< the state stopped being finite or physical
  std::string message;                   ///< why, when blown_up
  // The fold monitor: det F of the free elements at the checks (check_folding).
  std::int64_t fold_checks = 0;          ///< checks so far
  double min_det_f = 1;                  ///< smallest det F at the last check (1 before any)
  std::int64_t inverted_elements = 0;    ///< free elements with det F ≤ 0 at the last check
  double lowest_det_f = 1;               ///< smallest det F over all checks
  std::int64_t folded_checks = 0;        ///< checks that found an element with det F ≤ 0
  std::int64_t first_fold_update = -1;   ///< `count` at the first such check; −1: never folded
  double fold_check_wall_s = 0;          ///< wall time the checks took (s), download included
  bool folded() const { return folded_checks > 0; }
};

class HapticProbe {
 public:
  /// Uploads the model (the scene's indenter `options.probe` must be a sphere; its scripted path
  /// is replaced by set_probe_position). The probe starts where the scene puts it at t = 0.
  /// The scene, lattice and context must outlive the probe.
  HapticProbe(const Scene& scene, const Lattice& lattice, const ElementArrays& elements, const ClContext& cl,
              HapticOptions options = {});
  ~HapticProbe();
  HapticProbe(const HapticProbe&) = delete;
  HapticProbe& operator=(const HapticProbe&) = delete;

  /// Where the device's probe should go (m, world); thread-safe, returns at once.
  void set_probe_position(const Vec3& x_m);
  /// Force of the tissue on the probe at the commanded position (N, world): the last update's
  /// force plus K·(commanded − simulated position), zero where that would reverse the last
  /// force (the contact only pushes). Thread-safe; microseconds.
  Vec3 force() const;
  /// The last update (a copy); thread-safe.
  HapticUpdate last_update() const;

  /// Starts the update thread (updates back to back until stop() or a blow-up).
  void start();
  void stop();
  /// One update on the calling thread (not while the thread runs); false once blown up.
  bool update();
  /// Blocks until `count` updates are done or the probe blew up; false on blow-up.
  bool wait_for_updates(std::int64_t count) const;
  /// A fold check now (one state download, det F on the host), on the calling thread and not
  /// while the thread runs; update() makes them on its own (HapticOptions::fold_check_move).
  void check_fold();

  const Simulator& simulator() const { return sim_; }
  double spacing_m() const { return spacing_m_; }

 private:
  void run_thread();
  /// Broyden's update of K from the secant (dx, dF), then projected (see the header comment).
  void update_stiffness(const Vec3& dx, const Vec3& dF, std::int64_t contact_elements);

  HapticOptions options_;
  const Lattice& lattice_;
  const ElementArrays& elements_;
  Simulator sim_;
  double spacing_m_ = 0, F_ref_ = 0, extent_m_ = 0, max_stiffness_n_m_ = 0;
  std::int64_t steps_per_update_ = 1;
  Eigen::Matrix3d K_ = Eigen::Matrix3d::Zero();
  Vec3 secant_from_m_ = Vec3::Zero(), secant_force_n_ = Vec3::Zero();  ///< probe and force before its last move
  // The fold monitor's state (deformation thread only).
  Vec3 fold_checked_at_m_ = Vec3::Zero();  ///< simulated probe position at the last check
  std::chrono::steady_clock::time_point fold_checked_when_{};  ///< and its wall time
  std::vector<double> fold_u_, fold_v_;    ///< downloaded state, kept to avoid reallocating

  mutable std::mutex mutex_;               ///< guards commanded_ and last_
  Vec3 commanded_m_ = Vec3::Zero();
  HapticUpdate last_;
  std::atomic<bool> running_{false};
  std::thread thread_;
};

}  // namespace vb
