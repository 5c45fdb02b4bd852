// The gather floor (engine/bench/gather_floor.hpp) must read exactly what the step reads: each
// stage's XOR of the element's own words and its 26 neighbours' (the element itself where a cell
// is empty; their velocities only with dashpots), checked word for word against the lattice's own
// neighbour lists on the host, on a box with holes and a held layer, in both orders of the
// corrector, in groups of 32 or the device's choice, with and without dashpots. A kernel that
// skipped, repeated or misplaced a neighbour would change a word.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "engine/bench/gather_floor.hpp"
#include "engine/lattice/lattice.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb::bench {
namespace {

/// 7 × 5 × 4 voxels with a few left empty (neighbours missing inside the box, not only at its
/// edges); the bottom layer held.
Lattice holed_box() {
  LabelVolume v;
  v.dims = {7, 5, 4};
  v.spacing_m = 0.002;
  v.tissue_names = {"soft"};
  v.labels.assign(7 * 5 * 4, 1);
  for (const auto& [i, j, k] : std::vector<std::array<int, 3>>{{3, 2, 1}, {0, 0, 2}, {6, 4, 3}, {2, 3, 2}, {4, 1, 3}})
    v.labels[v.linear_index(i, j, k)] = 0;
  return build_lattice(v);
}

/// The neighbour the step reads in direction d: the element itself where the cell is empty.
std::vector<std::size_t> read_neighbours(const Lattice& lat, std::size_t e) {
  std::vector<std::size_t> out;
  for (const std::int32_t j : lat.neighbours(e)) out.push_back(j >= 0 ? std::size_t(j) : e);
  return out;
}

void check_floor(std::size_t work_group, bool reverse, bool dashpots) {
  const Lattice lat = holed_box();
  const std::size_t n = lat.element_count();
  std::vector<double> w(n);
  for (std::size_t e = 0; e < n; ++e) w[e] = lat.voxel_ijk(e)[2] == 0 ? 0.0 : 1.25e5;
  GatherFloor floor(test::cl_context(), lat, w, work_group, reverse, 4, dashpots);
  const std::string config = "group " + std::to_string(work_group) + (reverse ? ", reversed" : "") +
                             (dashpots ? ", dashpots" : ", no dashpots");
  const std::vector<cl_uint> u = floor.read_u(), v = floor.read_v(), E = floor.read_modulus();

  floor.enqueue_predict();
  const std::vector<cl_uint> up = floor.read_u_pred(), vp = floor.read_v_pred();
  std::size_t wrong = 0;
  for (std::size_t e = 0; e < n; ++e) {
    cl_uint vx = v[4 * e];
    if (w[e] != 0) {
      cl_uint acc = E[e];
      for (const std::size_t j : read_neighbours(lat, e))
        for (const std::size_t c : {0, 1, 2}) acc ^= u[4 * j + c] ^ (dashpots ? v[4 * j + c] : 0u);
      vx ^= acc;
    }
    const cl_uint want[6] = {u[4 * e], u[4 * e + 1], u[4 * e + 2], vx, v[4 * e + 1], v[4 * e + 2]};
    const cl_uint got[6] = {up[4 * e], up[4 * e + 1], up[4 * e + 2], up[4 * e + 3], vp[2 * e], vp[2 * e + 1]};
    for (int c = 0; c < 6; ++c) wrong += want[c] != got[c];
  }
  EXPECT_EQ(wrong, 0u) << "predictor, " << config;

  floor.enqueue_correct();
  const std::vector<cl_uint> u2 = floor.read_u(), v2 = floor.read_v();
  wrong = 0;
  for (std::size_t e = 0; e < n; ++e) {
    cl_uint ux = u[4 * e], vx = v[4 * e];
    if (w[e] != 0) {
      cl_uint acc = E[e] ^ up[4 * e] ^ up[4 * e + 1] ^ up[4 * e + 2] ^ up[4 * e + 3] ^ vp[2 * e] ^ vp[2 * e + 1];
      for (const std::size_t j : read_neighbours(lat, e)) {
        acc ^= up[4 * j] ^ up[4 * j + 1] ^ up[4 * j + 2];
        if (dashpots) acc ^= up[4 * j + 3] ^ vp[2 * j] ^ vp[2 * j + 1];  // ṽx, ṽy, ṽz
      }
      ux ^= acc;
      vx ^= acc >> 1;
    }
    wrong += u2[4 * e] != ux || v2[4 * e] != vx;
    for (const std::size_t c : {1, 2, 3}) wrong += u2[4 * e + c] != u[4 * e + c] || v2[4 * e + c] != v[4 * e + c];
  }
  EXPECT_EQ(wrong, 0u) << "corrector, " << config;

  const double rate = floor.steps_per_s(0.01);
  EXPECT_TRUE(std::isfinite(rate) && rate > 0) << rate;
}

TEST(GatherFloor, ReadsWhatTheStepReads) {
  for (const std::size_t group : {std::size_t(0), std::size_t(32)})
    for (const bool reverse : {false, true})
      for (const bool dashpots : {true, false}) check_floor(group, reverse, dashpots);
}

}  // namespace
}  // namespace vb::bench
