// Mesh writers (.vtp, .ply, .stl, .vtu): sizes, headers, data read back, atomic writing. VTK's own
// readers check the same files in tests/io/check_meshes_vtk.py, through MeshFilesForVtk below.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "engine/error.hpp"
#include "engine/surface/enclosed_volume.hpp"
#include "engine/surface/surface_elements.hpp"
#include "engine/surface/surface_mesh.hpp"
#include "io/lattice_vtu.hpp"
#include "io/surface_mesh_files.hpp"
#include "io/vtk_xml_arrays.hpp"
#include "tests/engine/surface/mesh_checks.hpp"

namespace fs = std::filesystem;

namespace vb {
namespace {

std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::vector<unsigned char> base64_decode(const std::string& text) {
  auto value = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    return c == '+' ? 62 : c == '/' ? 63 : -1;
  };
  std::vector<unsigned char> out;
  unsigned buffer = 0;
  int bits = 0;
  for (const char c : text) {
    const int v = value(c);
    if (v < 0) continue;
    buffer = buffer << 6 | unsigned(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back((unsigned char)(buffer >> bits & 0xff));
    }
  }
  return out;
}

/// The decoded values of the first DataArray whose opening tag contains `marker` (an attribute)
/// or that follows it (an element such as "<Points>").
template <class T>
std::vector<T> vtk_array(const std::string& xml, const std::string& marker) {
  auto at = xml.find(marker);
  if (at == std::string::npos) return {};
  if (marker[0] == '<') at = xml.find("<DataArray", at);
  const auto begin = xml.find('>', at) + 1, end = xml.find('<', begin);
  const auto bytes = base64_decode(xml.substr(begin, end - begin));
  if (bytes.size() < 8) {
    ADD_FAILURE() << "no binary data for " << marker;
    return {};
  }
  std::uint64_t count = 0;
  std::memcpy(&count, bytes.data(), 8);
  EXPECT_EQ(count + 8, bytes.size()) << marker;
  std::vector<T> values(count / sizeof(T));
  std::memcpy(values.data(), bytes.data() + 8, count);
  return values;
}

Lattice sphere_lattice(double h = 0.002) {
  return test::lattice_where({12, 12, 12}, [](int i, int j, int k) {
    return std::pow(i - 5.6, 2) + std::pow(j - 5.4, 2) + std::pow(k - 5.5, 2) <= 4.6 * 4.6;
  }, h);
}

class MeshFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("vb_mesh_files_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST(VtkXml, Base64MatchesRfc4648Vectors) {
  EXPECT_EQ(vtk_xml::base64("", 0), "");
  EXPECT_EQ(vtk_xml::base64("f", 1), "Zg==");
  EXPECT_EQ(vtk_xml::base64("fo", 2), "Zm8=");
  EXPECT_EQ(vtk_xml::base64("foo", 3), "Zm9v");
  EXPECT_EQ(vtk_xml::base64("foobar", 6), "Zm9vYmFy");
  const unsigned char high[] = {0xff, 0xfe, 0x00};
  EXPECT_EQ(vtk_xml::base64(high, 3), "//4A");
}

TEST_F(MeshFiles, VtpHoldsPositionsTrianglesAndVertexFields) {
  const Lattice lat = sphere_lattice();
  const SurfaceMesh mesh = build_surface(lat);
  std::vector<double> u(3 * lat.element_count()), stress(lat.element_count());
  for (std::size_t e = 0; e < lat.element_count(); ++e) {
    u[3 * e + 2] = -0.001 * double(e % 5);
    stress[e] = 100.0 * double(e);
  }
  const std::vector<double> x = element_positions_m(lat, u);
  write_surface_vtp((dir_ / "s.vtp").string(), mesh, x, u, {{"von_mises_stress_pa", stress, 1}});
  const std::string xml = read_all(dir_ / "s.vtp");
  EXPECT_NE(xml.find("NumberOfPoints=\"" + std::to_string(mesh.vertex_count()) + "\""), std::string::npos);
  EXPECT_NE(xml.find("NumberOfPolys=\"" + std::to_string(mesh.triangles.size()) + "\""), std::string::npos);
  const auto points = vtk_array<double>(xml, "<Points>");
  const auto disp = vtk_array<double>(xml, "Name=\"displacement_mm\"");
  const auto s = vtk_array<double>(xml, "Name=\"von_mises_stress_pa\"");
  const auto conn = vtk_array<std::int64_t>(xml, "Name=\"connectivity\"");
  const auto offs = vtk_array<std::int64_t>(xml, "Name=\"offsets\"");
  ASSERT_EQ(points.size(), 3 * mesh.vertex_count());
  ASSERT_EQ(disp.size(), 3 * mesh.vertex_count());
  ASSERT_EQ(s.size(), mesh.vertex_count());
  ASSERT_EQ(conn.size(), 3 * mesh.triangles.size());
  ASSERT_EQ(offs.size(), mesh.triangles.size());
  EXPECT_EQ(offs.back(), std::int64_t(conn.size()));
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    const std::size_t e = mesh.element_of_vertex[v];
    for (int c = 0; c < 3; ++c) {
      EXPECT_DOUBLE_EQ(points[3 * v + c], 1000 * x[3 * e + c]);
      EXPECT_DOUBLE_EQ(disp[3 * v + c], 1000 * u[3 * e + c]);
    }
    EXPECT_EQ(s[v], stress[e]);
  }
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(conn[3 * t + k], std::int64_t(mesh.triangles[t][k]));
}

TEST_F(MeshFiles, PlyAndStlHaveTheTrianglesInMillimetres) {
  const Lattice lat = sphere_lattice();
  const SurfaceMesh mesh = build_surface(lat);
  const std::vector<double> x = element_positions_m(lat);
  write_surface_stl((dir_ / "s.stl").string(), mesh, x);
  write_surface_ply((dir_ / "s.ply").string(), mesh, x);
  const std::string stl = read_all(dir_ / "s.stl");
  ASSERT_EQ(stl.size(), 84 + 50 * mesh.triangles.size());
  EXPECT_NE(stl.substr(0, 5), "solid");
  std::uint32_t count = 0;
  std::memcpy(&count, stl.data() + 80, 4);
  EXPECT_EQ(count, mesh.triangles.size());
  // Volume from the STL facets (mm³) = the enclosed volume.
  double six_v = 0;
  for (std::size_t t = 0; t < count; ++t) {
    float f[12];
    std::memcpy(f, stl.data() + 84 + 50 * t, sizeof f);
    const Eigen::Vector3d a(f[3], f[4], f[5]), b(f[6], f[7], f[8]), c(f[9], f[10], f[11]), n(f[0], f[1], f[2]);
    six_v += a.dot(b.cross(c));
    EXPECT_NEAR(n.dot((b - a).cross(c - a).normalized()), 1.0, 1e-5);
  }
  EXPECT_NEAR(six_v / 6, enclosed_volume_m3(mesh, x) * 1e9, 1e-3);

  const std::string ply = read_all(dir_ / "s.ply");
  const std::string header_end = "end_header\n";
  const auto body = ply.find(header_end) + header_end.size();
  const std::string header = ply.substr(0, body);
  EXPECT_NE(header.find("format binary_little_endian 1.0"), std::string::npos);
  EXPECT_NE(header.find("element vertex " + std::to_string(mesh.vertex_count()) + "\n"), std::string::npos);
  EXPECT_NE(header.find("element face " + std::to_string(mesh.triangles.size()) + "\n"), std::string::npos);
  EXPECT_EQ(ply.size(), body + 12 * mesh.vertex_count() + 13 * mesh.triangles.size());
}

TEST_F(MeshFiles, VtuHasEveryElementAndEveryCompleteCell) {
  const Lattice lat = sphere_lattice();
  const std::vector<double> x = element_positions_m(lat);
  write_lattice_vtu((dir_ / "l.vtu").string(), lat, x);
  const std::string xml = read_all(dir_ / "l.vtu");
  const std::size_t cells = count_complete_dual_cells(lat);
  EXPECT_EQ(cells, build_surface(lat).complete_cell_count);
  EXPECT_NE(xml.find("NumberOfPoints=\"" + std::to_string(lat.element_count()) + "\""), std::string::npos);
  EXPECT_NE(xml.find("NumberOfCells=\"" + std::to_string(cells) + "\""), std::string::npos);
  const auto conn = vtk_array<std::int64_t>(xml, "Name=\"connectivity\"");
  const auto types = vtk_array<std::uint8_t>(xml, "Name=\"types\"");
  ASSERT_EQ(conn.size(), 8 * cells);
  ASSERT_EQ(types.size(), cells);
  for (const auto t : types) EXPECT_EQ(t, 12);
  // VTK order: corner k of each hexahedron sits at lattice offset (k&1 ^ k>>1&1, k>>1&1, k>>2).
  for (std::size_t c = 0; c < cells; ++c) {
    const auto base = lat.voxel_ijk(std::size_t(conn[8 * c]));
    for (int k = 0; k < 8; ++k) {
      const auto ijk = lat.voxel_ijk(std::size_t(conn[8 * c + k]));
      const int dx = (k & 1) ^ (k >> 1 & 1), dy = k >> 1 & 1, dz = k >> 2;
      EXPECT_EQ(ijk[0] - base[0], dx);
      EXPECT_EQ(ijk[1] - base[1], dy);
      EXPECT_EQ(ijk[2] - base[2], dz);
    }
  }
}

TEST_F(MeshFiles, WritingIsAtomicAndChecksSizes) {
  const Lattice lat = sphere_lattice();
  const SurfaceMesh mesh = build_surface(lat);
  const std::vector<double> x = element_positions_m(lat);
  const std::vector<double> short_field(3);
  EXPECT_THROW(write_surface_vtp((dir_ / "bad.vtp").string(), mesh, x, {}, {{"bad", short_field, 1}}), Error);
  EXPECT_THROW(write_lattice_vtu((dir_ / "bad.vtu").string(), lat, std::span(x).first(6)), Error);
  EXPECT_THROW(write_surface_stl((dir_ / "no_such_dir" / "s.stl").string(), mesh, x), Error);
  write_surface_vtp((dir_ / "ok.vtp").string(), mesh, x);
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir_)) names.push_back(entry.path().filename().string());
  EXPECT_EQ(names, std::vector<std::string>{"ok.vtp"});  // no temporary files left behind
}

/// Writes meshes for tests/io/check_meshes_vtk.py (VTK's own readers) into
/// $VOXBREAST_MESH_CHECK_DIR with expected.json; skipped when the variable is unset.
TEST(MeshFilesForVtk, WriteMeshesAndExpectedCounts) {
  const char* out = std::getenv("VOXBREAST_MESH_CHECK_DIR");
  if (!out) GTEST_SKIP() << "run by tests/io/check_meshes_vtk.py (ctest check_meshes_vtk)";
  const fs::path dir(out);
  nlohmann::json expected;
  struct Case {
    std::string name;
    Lattice lattice;
  };
  std::vector<Case> cases;
  cases.push_back({"sphere", sphere_lattice()});
  // An edge pinch (one element, two vertices) in a mirrored (left-handed) frame.
  Lattice pinch = test::lattice_where({6, 6, 5}, [](int i, int j, int k) {
    return (i <= 2 && j <= 2) || (i >= 2 && i <= 4 && j >= 2 && j <= 4);
  });
  pinch.rotation = Eigen::Vector3d(1, -1, 1).asDiagonal();
  cases.push_back({"pinch_mirrored", pinch});
  for (const Case& c : cases) {
    const Lattice& lat = c.lattice;
    const SurfaceMesh mesh = build_surface(lat);
    std::vector<double> u(3 * lat.element_count()), strain(lat.element_count());
    for (std::size_t e = 0; e < lat.element_count(); ++e) {
      const Eigen::Vector3d p = lat.rest_position(e);
      u[3 * e + 1] = 0.05 * (p.z() - lat.origin_m.z());  // a shear: volume preserved
      strain[e] = 0.01 * double(e % 7);
    }
    const std::vector<double> rest = element_positions_m(lat), deformed = element_positions_m(lat, u);
    const std::vector<ElementField> fields{{"equivalent_strain", strain, 1}};
    write_surface_vtp((dir / (c.name + "_rest.vtp")).string(), mesh, rest, {}, fields);
    write_surface_vtp((dir / (c.name + "_deformed.vtp")).string(), mesh, deformed, u, fields);
    write_surface_ply((dir / (c.name + ".ply")).string(), mesh, deformed);
    write_surface_stl((dir / (c.name + ".stl")).string(), mesh, deformed);
    write_lattice_vtu((dir / (c.name + ".vtu")).string(), lat, deformed, u, fields);
    const double h_mm = lat.spacing_m * 1000;
    expected[c.name] = {
        {"points", mesh.vertex_count()},
        {"triangles", mesh.triangles.size()},
        {"elements", lat.element_count()},
        {"hexahedra", mesh.complete_cell_count},
        {"volume_mm3", double(mesh.complete_cell_count) * h_mm * h_mm * h_mm},
        {"max_displacement_mm", 1000 * *std::max_element(u.begin(), u.end())},
        {"point_arrays", {"displacement_mm", "Normals", "element", "equivalent_strain"}},
        {"tissues", lat.tissue_names},
    };
  }
  std::ofstream(dir / "expected.json") << expected.dump(2);
}

}  // namespace
}  // namespace vb
