// The surface-mesh observation of inverse fitting (docs/FIT.md, "Observation from a surface
// mesh"): the STL reader's round trip and its errors, the exact signed distance to a closed
// triangle mesh (a cube against its analytic distance, a sphere mesh against brute force, a voxel
// surface whose parts touch along an edge), and the surface distances of a translated box.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>

#include "engine/error.hpp"
#include "engine/fit/deformed_surface.hpp"
#include "engine/fit/mesh_distance.hpp"
#include "engine/fit/surface_observation.hpp"
#include "engine/lattice/voxelise.hpp"
#include "io/stl_file.hpp"
#include "io/triangle_mesh_files.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

/// An axis-aligned box [lo, hi] as 12 outward triangles.
TriangleMesh box_mesh(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  TriangleMesh m;
  for (int c = 0; c < 8; ++c) m.vertices_m.emplace_back(c & 1 ? hi.x() : lo.x(), c & 2 ? hi.y() : lo.y(), c & 4 ? hi.z() : lo.z());
  const std::uint32_t quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : quads) {
    m.triangles.push_back({q[0], q[1], q[2]});
    m.triangles.push_back({q[0], q[2], q[3]});
  }
  return m;
}

double box_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  const Eigen::Vector3d c = 0.5 * (lo + hi), half = 0.5 * (hi - lo);
  const Eigen::Vector3d q = (p - c).cwiseAbs() - half;
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

/// An icosphere of radius r: 20·4^levels triangles, outward.
TriangleMesh sphere_mesh(double r, int levels) {
  const double g = (1 + std::sqrt(5.0)) / 2;
  TriangleMesh m;
  for (const auto& v : std::vector<Eigen::Vector3d>{{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                                                    {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}})
    m.vertices_m.push_back(r * v.normalized());
  m.triangles = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                 {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8}, {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
    const auto middle = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto [it, added] = mid.try_emplace(key, std::uint32_t(m.vertices_m.size()));
      if (added) m.vertices_m.push_back(r * (m.vertices_m[a] + m.vertices_m[b]).normalized());
      return it->second;
    };
    std::vector<std::array<std::uint32_t, 3>> next;
    for (const auto& t : m.triangles) {
      const std::uint32_t a = middle(t[0], t[1]), b = middle(t[1], t[2]), c = middle(t[2], t[0]);
      next.insert(next.end(), {{t[0], a, c}, {t[1], b, a}, {t[2], c, b}, {a, b, c}});
    }
    m.triangles = next;
  }
  return m;
}

/// Brute force: the smallest distance to any triangle, by dense sampling of barycentric
/// coordinates refined around the best sample (independent of the closest-point code).
double brute_distance(const TriangleMesh& m, const Eigen::Vector3d& p) {
  double best = INFINITY;
  for (const auto& t : m.triangles) {
    const Eigen::Vector3d &a = m.vertices_m[t[0]], &b = m.vertices_m[t[1]], &c = m.vertices_m[t[2]];
    double u0 = 1.0 / 3, v0 = 1.0 / 3, span = 1.0;
    for (int round = 0; round < 12; ++round) {
      double bu = u0, bv = v0, bd = INFINITY;
      for (int i = -8; i <= 8; ++i)
        for (int j = -8; j <= 8; ++j) {
          const double u = std::clamp(u0 + span * i / 8, 0.0, 1.0), v = std::clamp(v0 + span * j / 8, 0.0, 1.0 - u);
          const double d = (a + u * (b - a) + v * (c - a) - p).norm();
          if (d < bd) bd = d, bu = u, bv = v;
        }
      u0 = bu, v0 = bv, span /= 3;
      best = std::min(best, bd);
    }
  }
  return best;
}

TEST(MeshDistance, CubeMatchesTheAnalyticSignedDistance) {
  const Eigen::Vector3d lo(0.01, -0.02, 0.005), hi(0.04, 0.01, 0.025);
  const MeshSignedDistance phi(box_mesh(lo, hi), "cube");
  EXPECT_NEAR(phi.enclosed_volume_m3(), 0.03 * 0.03 * 0.02, 1e-15);
  std::mt19937 random(3);
  std::uniform_real_distribution<double> x(-0.01, 0.06), y(-0.04, 0.03), z(-0.01, 0.04);
  int inside = 0;
  for (int i = 0; i < 3000; ++i) {  // face, edge and corner regions, inside and out
    const Eigen::Vector3d p(x(random), y(random), z(random));
    const double exact = box_distance(p, lo, hi);
    EXPECT_NEAR(phi.at(p), exact, 1e-15) << p.transpose();
    inside += exact < 0;
  }
  EXPECT_GT(inside, 100);
  EXPECT_NEAR(phi.winding_number(0.5 * (lo + hi)), 1.0, 1e-12);
  EXPECT_NEAR(phi.winding_number(Eigen::Vector3d(0.1, 0, 0)), 0.0, 1e-12);
}

TEST(MeshDistance, SphereMeshMatchesBruteForceAndIsTurnedOutward) {
  const double r = 0.02;
  TriangleMesh m = sphere_mesh(r, 2);  // 320 triangles
  for (auto& t : m.triangles) std::swap(t[1], t[2]);  // inward: the reader turns it
  const MeshSignedDistance phi(m, "sphere");
  EXPECT_GT(phi.enclosed_volume_m3(), 0.9 * 4.0 / 3 * M_PI * r * r * r);
  std::mt19937 random(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> radius(0.2 * r, 1.8 * r);
  for (int i = 0; i < 60; ++i) {
    const Eigen::Vector3d p = radius(random) * Eigen::Vector3d(normal(random), normal(random), normal(random)).normalized();
    const double d = phi.at(p), brute = brute_distance(m, p);
    EXPECT_NEAR(std::abs(d), brute, 1e-9) << p.transpose();
    EXPECT_EQ(d < 0, phi.winding_number(p) > 0.5) << p.transpose();
    // the polyhedron lies inside the sphere, within its sagitta (< 0.4 mm at 320 triangles)
    EXPECT_NEAR(d, p.norm() - r, 4e-4);
  }
}

TEST(MeshDistance, VoxelSurfaceWithPartsTouchingAlongAnEdgeHasTheRightSign) {
  // two voxels that share only an edge: the edge has four triangles, its ends two fans each
  Scene s = test::box_scene(1, 1, 2, 0.002);
  ShapeSpec second = s.model.shapes[0];
  second.min_m = Vec3(0.002, 0.002, 0);
  second.max_m = Vec3(0.004, 0.004, 0.004);
  s.model.shapes.push_back(second);
  const Lattice lattice = build_lattice(voxelise_shapes(s));
  ASSERT_EQ(lattice.element_count(), 4u);
  const TriangleMesh m = deformed_boundary_mesh(lattice, std::vector<double>(12, 0.0), -1);
  const MeshSignedDistance phi(m, "voxels");
  EXPECT_NEAR(phi.enclosed_volume_m3(), 4 * 0.002 * 0.002 * 0.002, 1e-18);
  std::mt19937 random(11);
  std::uniform_real_distribution<double> x(-0.002, 0.006), z(-0.001, 0.005);
  for (int i = 0; i < 400; ++i) {
    const Eigen::Vector3d p = lattice.affine().topRightCorner<3, 1>() + Eigen::Vector3d(x(random), x(random), z(random));
    EXPECT_EQ(phi.at(p) < 0, phi.winding_number(p) > 0.5) << p.transpose();
    EXPECT_NEAR(std::abs(phi.at(p)), brute_distance(m, p), 1e-9);
  }
}

TEST(MeshDistance, RejectsOpenEmptyAndNonFiniteMeshes) {
  TriangleMesh open = box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  open.triangles.pop_back();
  try {
    MeshSignedDistance(open, "open.stl");
    FAIL() << "an open mesh was accepted";
  } catch (const Error& e) {
    EXPECT_NE(e.problem().find("not closed"), std::string::npos) << e.what();
    EXPECT_EQ(e.location(), "open.stl");
  }
  TriangleMesh flipped = box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  std::swap(flipped.triangles[0][1], flipped.triangles[0][2]);  // one triangle the wrong way round
  EXPECT_THROW(MeshSignedDistance(flipped, "flipped"), Error);
  EXPECT_THROW(MeshSignedDistance(TriangleMesh{}, "empty"), Error);
  TriangleMesh nan = box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  nan.vertices_m[3].x() = NAN;
  EXPECT_THROW(MeshSignedDistance(nan, "nan"), Error);
}

class StlFile : public ::testing::Test {
 protected:
  std::string path(const std::string& name) {
    const std::string dir = ::testing::TempDir() + "/vb_stl_" + std::to_string(::getpid());
    std::filesystem::create_directories(dir);
    return dir + "/" + name;
  }
  static void write(const std::string& p, const std::string& bytes) { std::ofstream(p, std::ios::binary) << bytes; }
  static std::string read(const std::string& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  static std::string error_of(const std::string& p) {
    try {
      read_stl(p);
    } catch (const Error& e) {
      EXPECT_EQ(e.location(), p);
      return e.problem();
    }
    return "no error";
  }
};

TEST_F(StlFile, BinaryRoundTripWeldsCornersInMillimetres) {
  const TriangleMesh box = box_mesh(Eigen::Vector3d(0.01, 0.02, 0.03), Eigen::Vector3d(0.02, 0.035, 0.04));
  const std::string p = path("box.stl");
  write_triangle_mesh_stl(p, box);
  const TriangleMesh back = read_stl(p);
  ASSERT_EQ(back.vertices_m.size(), 8u);  // welded from 36 corners
  ASSERT_EQ(back.triangles.size(), 12u);
  for (std::size_t t = 0; t < 12; ++t)
    for (int k = 0; k < 3; ++k)
      EXPECT_LT((back.vertices_m[back.triangles[t][k]] - box.vertices_m[box.triangles[t][k]]).norm(), 1e-9);
  EXPECT_NEAR(MeshSignedDistance(back, p).enclosed_volume_m3(), 0.01 * 0.015 * 0.01, 1e-12);
  // truncated, and a count that does not match the size
  const std::string bytes = read(p);
  write(path("cut.stl"), bytes.substr(0, bytes.size() - 20));
  EXPECT_NE(error_of(path("cut.stl")).find("truncated"), std::string::npos);
  write(path("long.stl"), bytes + std::string(50, '\0'));
  EXPECT_NE(error_of(path("long.stl")).find("header says 12 triangles"), std::string::npos);
  write(path("short.stl"), "xyz");
  EXPECT_NE(error_of(path("short.stl")).find("too short"), std::string::npos);
  std::string zero = bytes.substr(0, 84);
  std::fill(zero.begin() + 80, zero.end(), '\0');
  write(path("none.stl"), zero);
  EXPECT_NE(error_of(path("none.stl")).find("no triangle"), std::string::npos);
  std::string nan = bytes;
  const float bad = NAN;
  std::memcpy(nan.data() + 84 + 50 * 5 + 12 + 4, &bad, 4);
  write(path("nan.stl"), nan);
  EXPECT_NE(error_of(path("nan.stl")).find("facet 6"), std::string::npos);
}

TEST_F(StlFile, AsciiFacetsAndItsErrors) {
  const std::string facet =
      " facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 10 0 0\n   vertex 0 10 0\n  endloop\n endfacet\n";
  write(path("a.stl"), "solid tri\n" + facet + facet + "endsolid tri\n");
  const TriangleMesh m = read_stl(path("a.stl"));
  EXPECT_EQ(m.triangles.size(), 2u);
  EXPECT_EQ(m.vertices_m.size(), 3u);
  EXPECT_NEAR(m.vertices_m[1].x(), 0.010, 1e-15);  // mm → m
  write(path("cut.stl"), "solid tri\n" + facet + facet.substr(0, 60));
  EXPECT_NE(error_of(path("cut.stl")).find("truncated"), std::string::npos);
  write(path("end.stl"), "solid tri\n" + facet);
  EXPECT_NE(error_of(path("end.stl")).find("without 'endsolid'"), std::string::npos);
  std::string word = facet;
  word.replace(word.find("10 0 0"), 2, "1x");
  write(path("word.stl"), "solid tri\n" + word + "endsolid\n");
  EXPECT_NE(error_of(path("word.stl")).find("'1x'"), std::string::npos);
  std::string nan = facet;
  nan.replace(nan.find("10 0 0"), 2, "nan");
  write(path("nan.stl"), "solid tri\n" + nan + "endsolid\n");
  EXPECT_NE(error_of(path("nan.stl")).find("not a finite"), std::string::npos);
}

TEST(SurfaceMeshObservation, TranslatedBoxDistancesAreExact) {
  const double h = 0.003;
  const Scene s = test::box_scene(6, 6, 4, h);
  const Lattice lattice = build_lattice(voxelise_shapes(s));
  const std::size_t n = lattice.element_count();
  const Eigen::Vector3d t(0.0004, 0, -0.0015);
  std::vector<double> moved(3 * n), still(3 * n, 0.0);
  for (std::size_t e = 0; e < n; ++e)
    for (int a = 0; a < 3; ++a) moved[3 * e + a] = t[a];
  const TriangleMesh observed = deformed_boundary_mesh(lattice, moved, -1);
  EXPECT_EQ(observed.triangles.size(), std::size_t(2 * 2 * (6 * 6 + 6 * 4 + 6 * 4)));
  std::vector<std::unique_ptr<SurfaceDistance>> fields;
  fields.push_back(std::make_unique<MeshSignedDistance>(observed, "box"));
  const SurfaceData data(std::move(fields), lattice, surface_regions(s, lattice, {0}), std::vector<bool>(n, true),
                         [](const Eigen::Vector3d&) { return true; }, 0.001, "test");
  EXPECT_LT(data.stats(moved).max_m, 1e-15);  // the true motion lands exactly on it
  // unmoved: z faces 1.5 mm off (outside above, inside below), x faces 0.4 mm, y faces on it except
  // where the moved box's edge passes them by
  const std::vector<double> d = data.distances(still);
  int top = 0, bottom = 0, xs = 0;
  for (const double x : d) {
    top += std::abs(x - 0.0015) < 1e-15;
    bottom += std::abs(x + 0.0015) < 1e-15;
    xs += std::abs(std::abs(x) - 0.0004) < 1e-15;
  }
  EXPECT_GE(top, 30);     // the top faces away from the edges (inside the moved top's reach: 5×6)
  EXPECT_GE(bottom, 30);  // the bottom faces inside the moved box
  EXPECT_GE(xs, 2 * 6 * 3);
}

}  // namespace
}  // namespace vb
