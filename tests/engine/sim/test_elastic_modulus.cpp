// Small-strain stretch test of the spring-constant derivation: impose the homogeneous
// uniaxial-stress field u = ε·(−ν x, −ν y, z) on a free block and measure the lattice forces.
//  - every element off the surface is in equilibrium;
//  - every interior column of the end face carries exactly σ·h² = E·ε·h² (the bulk lattice is E);
//  - the whole end face, over the voxel area nx·ny·h², gives the block's effective E: surface
//    columns lack their outward diagonals, so it is slightly low, within 5% for ≥ 12 voxels across.
#include <gtest/gtest.h>

#include "engine/material/linear_spring.hpp"
#include "engine/sim/simulator.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

struct BlockSize {
  int nx, ny, nz;
};

class EffectiveModulus : public ::testing::TestWithParam<BlockSize> {};

TEST_P(EffectiveModulus, StretchReproducesYoungsModulus) {
  const auto [nx, ny, nz] = GetParam();
  // Springs are geometrically exact, so forces carry an O(ε) nonlinear part: ε = 1e-6 measures the
  // small-strain limit, and 10ε is the tolerance of the exact bulk checks.
  const double h = 0.002, E = 5000, strain = 1e-6, nu = linear_spring::poisson_ratio;
  Scene s = test::box_scene(nx, ny, nz, h, E);
  s.solver.precision = Precision::Double;
  s.solver.dashpot_ratio = 0.1;
  const auto m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  const std::size_t n = m.lattice.element_count();
  std::vector<double> u(3 * n), v(3 * n, 0.0);
  for (std::size_t e = 0; e < n; ++e) {
    const Vec3 X = m.lattice.rest_position(e);
    u[3 * e] = -nu * strain * X.x();
    u[3 * e + 1] = -nu * strain * X.y();
    u[3 * e + 2] = strain * X.z();
  }
  sim.upload(u, v);
  const auto f = sim.lattice_forces();
  const double column_force = E * strain * h * h;
  double face_force = 0;
  for (std::size_t e = 0; e < n; ++e) {
    const auto ijk = m.lattice.voxel_ijk(e);
    const bool lateral = ijk[0] == 0 || ijk[1] == 0 || ijk[0] == nx - 1 || ijk[1] == ny - 1;
    const bool end = ijk[2] == 0 || ijk[2] == nz - 1;
    const Vec3 fe(f[3 * e], f[3 * e + 1], f[3 * e + 2]);
    if (ijk[2] == nz - 1) face_force -= fe.z();  // springs pull the stretched end back
    if (!lateral && !end) EXPECT_LT(fe.norm(), 10 * strain * column_force) << "interior element " << e;
    if (!lateral && ijk[2] == nz - 1) EXPECT_NEAR(-fe.z() / column_force, 1.0, 10 * strain) << "end column " << e;
  }
  const double E_block = face_force / (nx * ny * h * h * strain);
  RecordProperty("E_block_over_E", std::to_string(E_block / E));
  EXPECT_NEAR(E_block / E, 1.0, 0.05) << nx << "x" << ny << "x" << nz << ": E_block = " << E_block;
}

INSTANTIATE_TEST_SUITE_P(Blocks, EffectiveModulus,
                         ::testing::Values(BlockSize{12, 12, 6}, BlockSize{16, 20, 8}, BlockSize{24, 24, 4}),
                         [](const auto& info) {  // e.g. 12x12x6
                           const BlockSize& b = info.param;
                           return std::to_string(b.nx) + "x" + std::to_string(b.ny) + "x" + std::to_string(b.nz);
                         });

}  // namespace
}  // namespace vb
