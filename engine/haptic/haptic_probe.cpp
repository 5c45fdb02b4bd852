#include "engine/haptic/haptic_probe.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "engine/error.hpp"
#include "engine/sim/run.hpp"

namespace vb {

HapticProbe::HapticProbe(const Scene& scene, const Lattice& lattice, const ElementArrays& elements,
                         const ClContext& cl, HapticOptions options)
    : options_(options), lattice_(lattice), elements_(elements), sim_(scene, lattice, elements, cl) {
  require(options.probe < scene.indenters.size(),
          "the haptic probe is indenter " + std::to_string(options.probe + 1) + ", but the scene has " +
              std::to_string(scene.indenters.size()) + " indenters",
          "indenter", "add a [[indenter]] with kind = \"sphere\" (its start is where the probe begins)");
  const IndenterSpec& probe = scene.indenters[options.probe];
  require(probe.kind == IndenterSpec::Kind::Sphere, "the haptic probe must be a sphere indenter",
          "indenter " + std::to_string(options.probe + 1) + (probe.line ? " (line " + std::to_string(probe.line) + ")" : ""));
  require(options.max_move_per_update > 0, "the probe's largest move per update must be positive",
          "max_move_per_update");
  require(options.fold_check_move > 0 && options.fold_check_every_s > 0,
          "the fold monitor's move and interval must be positive", "fold_check_move, fold_check_every_s");
  spacing_m_ = lattice.spacing_m;
  const EquilibriumScales scales = equilibrium_scales(lattice, elements);
  F_ref_ = scales.force_n;
  extent_m_ = scales.size_m;
  // Far above any contact stiffness of this probe (Hertz: 2E*·a with a ≤ R + h): a cap against
  // secant estimates gone wild, never a limit in a sane press.
  max_stiffness_n_m_ = 10 * (F_ref_ / (spacing_m_ * spacing_m_)) * (probe.radius_m + spacing_m_);
  steps_per_update_ = options.steps_per_update > 0 ? options.steps_per_update : std::max(1, scene.solver.check_every);
  commanded_m_ = probe.start_m;
  sim_.place_indenter(options.probe, probe.start_m);
  last_.probe_m = secant_from_m_ = probe.start_m;
}

HapticProbe::~HapticProbe() { stop(); }

void HapticProbe::set_probe_position(const Vec3& x_m) {
  std::lock_guard<std::mutex> lock(mutex_);
  commanded_m_ = x_m;
}

Vec3 HapticProbe::force() const {
  std::lock_guard<std::mutex> lock(mutex_);
  const Vec3 f = last_.force_n + last_.stiffness_n_m * (commanded_m_ - last_.probe_m);
  // The contact only pushes: a probe pulled back past the linearisation's zero gets no force,
  // never a pull.
  return f.dot(last_.force_n) > 0 ? f : Vec3::Zero();
}

HapticUpdate HapticProbe::last_update() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_;
}

void HapticProbe::start() {
  if (running_.exchange(true)) return;
  thread_ = std::thread([this] { run_thread(); });
}

void HapticProbe::stop() {
  running_ = false;
  if (thread_.joinable()) thread_.join();
}

void HapticProbe::run_thread() {
  try {
    while (running_ && update()) {
    }
  } catch (const std::exception& e) {  // an OpenCL failure: report it as the end of the run
    std::lock_guard<std::mutex> lock(mutex_);
    last_.blown_up = true;
    last_.message = std::string("deformation update failed: ") + e.what();
  }
  running_ = false;
}

bool HapticProbe::wait_for_updates(std::int64_t count) const {
  for (;;) {
    const HapticUpdate u = last_update();
    if (u.blown_up) return false;
    if (u.count >= count) return true;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
}

bool HapticProbe::update() {
  Vec3 target, from;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (last_.blown_up) return false;
    target = commanded_m_;
    from = last_.probe_m;
  }
  // The probe follows the command, at most max_move_per_update spacings per update, along a
  // straight path over the update's steps (a jump would push elements a long way in one step).
  const double max_move = options_.max_move_per_update * spacing_m_;
  Vec3 to = target;
  if ((to - from).norm() > max_move) to = from + (to - from).normalized() * max_move;
  const double t0 = sim_.time_s();
  sim_.set_indenter_motion(options_.probe,
                           IndenterMotion::straight(from, to, t0, t0 + double(steps_per_update_) * sim_.dt_s()));
  sim_.advance(steps_per_update_);
  const StateCheck c = sim_.check();

  std::string trouble;
  if (c.nonfinite_elements > 0)
    trouble = std::to_string(c.nonfinite_elements) + " elements have non-finite state";
  else if (c.max_speed_m_s * sim_.dt_s() > 0.5 * spacing_m_)
    trouble = "an element moves more than half a spacing per step";
  else if (c.max_displacement_m > 10 * extent_m_)
    trouble = "displacement exceeds ten times the model size";
  const Vec3 force = c.indenter_force_n[options_.probe];
  if (trouble.empty() && !force.allFinite()) trouble = "the probe force is not finite";

  bool first_check = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!trouble.empty()) {
      std::ostringstream msg;
      msg << "the deformation blew up at update " << last_.count + 1 << " (step " << sim_.steps() << "): " << trouble
          << "; use a smaller solver.dt, more damping or slower probe moves";
      last_.blown_up = true;
      last_.message = msg.str();
      return false;
    }
    if ((to - from).norm() > 1e-4 * spacing_m_) secant_from_m_ = from, secant_force_n_ = last_.force_n;
    update_stiffness(to - secant_from_m_, force - secant_force_n_, c.contact_elements[options_.probe]);
    last_.count += 1;
    last_.probe_m = to;
    last_.force_n = force;
    last_.stiffness_n_m = K_;
    last_.contact_elements = c.contact_elements[options_.probe];
    last_.residual = c.residual_ratio;
    last_.steps = sim_.steps();
    first_check = last_.fold_checks == 0;
  }
  // The fold monitor, outside the lock (force() keeps answering): a check costs a state download
  // and one host pass over the elements (3–8 ms for 4,000–10,000 elements with PoCL on 2 loaded
  // cores), so it runs at the first update, when the probe has moved half a spacing since the
  // last one — the travel over which an element layer can be pushed through the next — and every
  // 0.25 s of wall time while it holds (the defaults of HapticOptions).
  // Wall time, not simulated time: the relaxation's time is fictitious, the check's cost is real.
  if (first_check || (to - fold_checked_at_m_).norm() >= options_.fold_check_move * spacing_m_ ||
      std::chrono::steady_clock::now() - fold_checked_when_ >= std::chrono::duration<double>(options_.fold_check_every_s))
    check_fold();
  return true;
}

void HapticProbe::check_fold() {
  const auto start = std::chrono::steady_clock::now();
  sim_.download(fold_u_, fold_v_);
  const FoldCheck c = check_folding(lattice_, fold_u_, elements_.inverse_mass);
  const double min_det_f = std::isfinite(c.min_det_f) ? c.min_det_f : 1.0;  // no free elements: nothing folds
  fold_checked_when_ = std::chrono::steady_clock::now();
  std::lock_guard<std::mutex> lock(mutex_);
  fold_checked_at_m_ = last_.probe_m;
  last_.fold_checks += 1;
  last_.min_det_f = min_det_f;
  last_.inverted_elements = c.inverted_elements;
  last_.lowest_det_f = std::min(last_.lowest_det_f, min_det_f);
  if (c.inverted_elements > 0) {
    if (last_.folded_checks == 0) last_.first_fold_update = last_.count;
    last_.folded_checks += 1;
  }
  last_.fold_check_wall_s += std::chrono::duration<double>(fold_checked_when_ - start).count();
}

void HapticProbe::update_stiffness(const Vec3& dx, const Vec3& dF, std::int64_t contact_elements) {
  if (contact_elements == 0) {  // free space: no force, nothing to linearise
    K_.setZero();
    return;
  }
  // Only moves well above round-off teach anything; a held probe keeps its K while the force relaxes.
  if (dx.norm() < 1e-4 * spacing_m_) return;
  K_ += (dF - K_ * dx) * dx.transpose() / dx.squaredNorm();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(0.5 * (K_ + K_.transpose()));
  const Eigen::Vector3d lambda = eig.eigenvalues().cwiseMax(-max_stiffness_n_m_).cwiseMin(0.0);
  K_ = eig.eigenvectors() * lambda.asDiagonal() * eig.eigenvectors().transpose();
}

}  // namespace vb
