// New moduli for a built model (Simulator::set_materials): what depends on them is the arena's
// modulus slot and material table, dt and relaxation's mass scale; everything else a simulator
// builds (buffers, program, grid, surface) is the model's geometry and stays, and its state,
// clock, gravity, indenters and relaxation estimate go back to where a new simulator starts them.
#include <cmath>

#include "engine/error.hpp"
#include "engine/sim/kernel_arg_layout.hpp"
#include "engine/sim/simulator.hpp"

namespace vb {

void Simulator::set_materials(const ElementArrays& el) {
  const char* where = "fit (new moduli for the model)";
  require(el.youngs_modulus_pa.size() == n_ && el.stability_modulus_pa.size() == n_ && el.displacement_m.size() == 3 * n_,
          "the new moduli are not one per element of the model", where);
  require(el.inverse_mass == inverse_mass_, "the new element arrays have other masses or held elements than the model",
          where, "build a new simulator");
  require(el.hyperelastic == hyper_ && el.biphasic == biphasic_ &&
              (material_rows_ == 0 || el.material_table.size() == material_rows_),
          "the new element arrays have other material laws than the model", where, "build a new simulator");
  require(!tri_contact_, "new moduli with triangle contact (its penalty stiffness follows them)", where,
          "build a new simulator");
  const TimeStepChoice dt = choose_time_step(scene_, lattice_, el);
  require(dt.dt_s > 0 && std::isfinite(dt.dt_s), "time step must be positive and finite", "solver.dt");

  const std::vector<unsigned char> E = real_bytes(device_modulus(el.youngs_modulus_pa));
  cl_.queue.enqueueWriteBuffer(E_, CL_TRUE, 0, E.size(), E.data());
  if (material_rows_) {
    std::vector<double> table;
    for (const auto& row : el.material_table) table.insert(table.end(), row.begin(), row.end());
    const std::vector<unsigned char> bytes = real_bytes(table);
    cl_.queue.enqueueWriteBuffer(materials_, CL_TRUE, 0, bytes.size(), bytes.data());
  }
  write_check_scale(el);
  dt_ = dt;
  set_time_step_args();
  steps_ = 0;
  if (scene_.gravity.active) set_gravity(scene_.gravity.acceleration_m_s2);
  for (std::size_t i = 0; i < scene_.indenters.size(); ++i) set_indenter_motion(i, starting_motion(scene_.indenters[i]));
  path_segment_.assign(scene_.indenters.size(), std::size_t(-1));
  upload(el.displacement_m, std::vector<double>(3 * n_, 0.0));
  if (relax_) {
    const std::vector<unsigned char> scale = real_bytes(relaxation_mass_scale(el, dt_.row_stiffness_n_m));
    dt_.row_stiffness_n_m = {};
    cl_.queue.enqueueWriteBuffer(relax_scale_, CL_TRUE, 0, scale.size(), scale.data());
    // as the constructor leaves it: no estimate of ω_min² yet, no damping, and the previous
    // check's state the rest state (zeros), valid while the held elements sit there
    relax_omega_sq_ = INFINITY;
    damping_ = 0;
    set_real(relax_kernel_, kStepIndenter + kIndenterArgs + 3, damping_);
    cl_.queue.enqueueFillBuffer(relax_prev_, cl_uchar(0), 0, 2 * 4 * real_size_ * n_);
    cl_.queue.finish();
    relax_prev_valid_ = relax_from_rest_valid_;
  }
}

}  // namespace vb
