// A lattice whose axes are rotated in the world (an oblique CT) must give the rotated answer of
// the same lattice axis-aligned: u_rotated = R·u_aligned when gravity is rotated along.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "engine/lattice/voxelise.hpp"
#include "engine/sim/simulator.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

std::vector<double> settle(const Eigen::Matrix3d& R, const Vec3& gravity_world) {
  Scene s = test::box_scene(5, 4, 6, 0.002);
  s.gravity.active = true;
  s.gravity.acceleration_m_s2 = gravity_world;
  s.solver.precision = Precision::Double;
  s.solver.dashpot_ratio = 0.2;
  s.solver.damping_per_s = 20;
  LabelVolume vol = voxelise_shapes(s);
  vol.rotation = R;
  test::Model m;
  m.lattice = build_lattice(vol);
  m.elements = make_element_arrays(s, m.lattice);
  for (std::size_t e = 0; e < m.lattice.element_count(); ++e)  // hold the k = 0 layer
    if (m.lattice.voxel_ijk(e)[2] == 0) m.elements.inverse_mass[e] = 0;
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  sim.advance(300);
  std::vector<double> u, v;
  sim.download(u, v);
  return u;
}

TEST(RotatedLattice, DisplacementRotatesWithTheLattice) {
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized()) *
                             Eigen::AngleAxisd(-0.3, Vec3::UnitX())).toRotationMatrix();
  const Vec3 g(0.3, -0.5, -9.81);
  const auto aligned = settle(Eigen::Matrix3d::Identity(), R.transpose() * g);
  const auto rotated = settle(R, g);
  double max_u = 0, max_err = 0;
  for (std::size_t e = 0; e < aligned.size() / 3; ++e) {
    const Vec3 ua(aligned[3 * e], aligned[3 * e + 1], aligned[3 * e + 2]);
    const Vec3 ur(rotated[3 * e], rotated[3 * e + 1], rotated[3 * e + 2]);
    max_u = std::max(max_u, ua.norm());
    max_err = std::max(max_err, (R * ua - ur).norm());
  }
  ASSERT_GT(max_u, 0);
  EXPECT_LT(max_err, 1e-9 * max_u);
}

}  // namespace
}  // namespace vb
