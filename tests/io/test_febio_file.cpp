// The FEBio export: the dual cells as hex8 elements read back onto the lattice (counts, positions,
// connectivity, orientation), held elements as the fixed node set, gravity as the body load, and
// each hyperelastic law as an FEBio material with the same strain energy.
#include <gtest/gtest.h>
#include <pugixml.hpp>
#include <unistd.h>

#include <Eigen/Dense>
#include <cmath>
#include <filesystem>
#include <map>
#include <random>
#include <sstream>

#include "engine/error.hpp"
#include "engine/lattice/dual_hexahedra.hpp"
#include "engine/material/hyperelastic.hpp"
#include "io/febio_file.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

/// An nx×ny×nz block of label 1 ("soft") with its top two layers label 2 ("stiff") and one voxel
/// sticking out of the top (a strand in no dual cell), in the frame `rotation`.
Lattice block_lattice(int nx, int ny, int nz, const Eigen::Matrix3d& rotation) {
  LabelVolume v;
  v.dims = {nx, ny, nz + 1};
  v.spacing_m = 0.003;
  v.origin_m = Eigen::Vector3d(0.01, -0.02, 0.005);
  v.rotation = rotation;
  v.tissue_names = {"soft", "stiff"};
  v.labels.assign(std::size_t(nx) * ny * (nz + 1), 0);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) v.labels[v.linear_index(i, j, k)] = k >= nz - 2 ? 2 : 1;
  v.labels[v.linear_index(0, 0, nz)] = 1;
  return build_lattice(v);
}

double hex_volume_sign(const std::array<Eigen::Vector3d, 8>& x) {
  return (x[1] - x[0]).cross(x[3] - x[0]).dot(x[4] - x[0]);
}

std::vector<double> split_numbers(const std::string& text) {
  std::vector<double> out;
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, ',')) out.push_back(std::stod(item));
  return out;
}

Eigen::Matrix3d mirrored_rotation() {
  Eigen::Matrix3d r = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  r.col(0) *= -1;  // a left-handed image frame
  return r;
}

TEST(DualHexahedra, OnePerBlockOfEightWithPositiveVolumeInEitherHandedness) {
  for (const Eigen::Matrix3d& rotation : {Eigen::Matrix3d(Eigen::Matrix3d::Identity()), mirrored_rotation()}) {
    const Lattice lat = block_lattice(4, 3, 5, rotation);
    const auto hexes = dual_hexahedra(lat);
    EXPECT_EQ(hexes.size(), 3u * 2u * 4u);
    for (const auto& hex : hexes) {
      std::array<Eigen::Vector3d, 8> x;
      for (int k = 0; k < 8; ++k) x[k] = lat.rest_position(hex[k]);
      EXPECT_NEAR(hex_volume_sign(x), std::pow(lat.spacing_m, 3), 1e-15) << "det " << rotation.determinant();
      for (int k = 0; k < 4; ++k) EXPECT_NEAR((x[k + 4] - x[k]).norm(), lat.spacing_m, 1e-15);
    }
  }
}

class FebioExport : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = (std::filesystem::temp_directory_path() / ("vb_febio_" + std::to_string(::getpid()) + ".feb")).string();
  }
  void TearDown() override { std::filesystem::remove(path_); }
  std::string path_;
};

TEST_F(FebioExport, MeshReadsBackOntoTheLattice) {
  const Lattice lat = block_lattice(4, 3, 5, mirrored_rotation());
  Scene scene;
  scene.materials["soft"] = test::validation_material("neo-hookean", 0.45);
  scene.materials["stiff"] = test::material("stiff", 9000, 1100);
  scene.gravity.active = true;
  scene.gravity.acceleration_m_s2 = Vec3(0, 9.81, -1);
  std::vector<bool> held(lat.element_count(), false);
  std::size_t held_count = 0;
  for (std::size_t e = 0; e < lat.element_count(); ++e)
    if (lat.voxel_ijk(e)[2] == 0) held[e] = true, ++held_count;

  const FebioExportSummary summary = write_febio(path_, scene, lat, held);
  const auto hexes = dual_hexahedra(lat);
  EXPECT_EQ(summary.hexahedra, hexes.size());
  EXPECT_EQ(summary.nodes, lat.element_count() - 1) << "all but the strand";
  EXPECT_EQ(summary.elements_left_out, 1u);
  EXPECT_EQ(summary.fixed_nodes, held_count);

  pugi::xml_document doc;
  ASSERT_TRUE(doc.load_file(path_.c_str()));
  const auto spec = doc.child("febio_spec");
  EXPECT_STREQ(spec.attribute("version").value(), "4.0");

  // nodes: the element centres, in element order, at their rest positions to the bit
  std::map<int, Eigen::Vector3d> node;
  for (auto n : spec.child("Mesh").child("Nodes").children("node")) {
    const auto x = split_numbers(n.text().get());
    ASSERT_EQ(x.size(), 3u);
    node[n.attribute("id").as_int()] = Eigen::Vector3d(x[0], x[1], x[2]);
  }
  ASSERT_EQ(node.size(), summary.nodes);
  std::vector<int> node_of_element(lat.element_count(), 0);
  int next = 0;
  for (std::size_t e = 0; e < lat.element_count(); ++e) {
    if (lat.voxel_ijk(e)[2] == 5) continue;  // the strand
    node_of_element[e] = ++next;
    EXPECT_EQ(node.at(next), lat.rest_position(e)) << "element " << e;
  }

  // elements: one per dual cell, the same corners, blocks per tissue (soft below, stiff on top)
  std::map<std::vector<int>, std::string> block_of_cell;
  int element_id = 0;
  for (auto block : spec.child("Mesh").children("Elements")) {
    EXPECT_STREQ(block.attribute("type").value(), "hex8");
    for (auto elem : block.children("elem")) {
      EXPECT_EQ(elem.attribute("id").as_int(), ++element_id);
      std::vector<int> corners;
      for (double c : split_numbers(elem.text().get())) corners.push_back(int(c));
      block_of_cell[corners] = block.attribute("name").value();
    }
  }
  EXPECT_EQ(block_of_cell.size(), hexes.size());
  for (const auto& hex : hexes) {
    std::vector<int> corners;
    for (std::uint32_t e : hex) corners.push_back(node_of_element[e]);
    ASSERT_TRUE(block_of_cell.count(corners));
    // the top cells are all stiff; below them four stiff and four soft corners tie, and a tie goes
    // to the tissue listed first
    int lowest = lat.dims[2];
    for (std::uint32_t e : hex) lowest = std::min(lowest, lat.voxel_ijk(e)[2]);
    EXPECT_EQ(block_of_cell[corners], lowest == 3 ? "stiff" : "soft");
  }

  // held elements are the fixed node set; gravity g is written as -g per unit mass
  const auto set = split_numbers(spec.child("Mesh").child("NodeSet").text().get());
  EXPECT_EQ(set.size(), held_count);
  for (double id : set) EXPECT_TRUE(held[std::size_t(id) - 1]);  // layer 0 comes first, ids = index + 1
  const auto bc = spec.child("Boundary").child("bc");
  EXPECT_STREQ(bc.attribute("node_set").value(), "held");
  const auto load = spec.child("Loads").child("body_load");
  EXPECT_EQ(load.child("x").text().as_double(), 0.0);
  EXPECT_EQ(load.child("y").text().as_double(), -9.81);
  EXPECT_EQ(load.child("z").text().as_double(), 1.0);

  // each tissue's material: the neo-Hookean one as Mooney-Rivlin with c1 = mu/2, c2 = 0
  std::map<std::string, pugi::xml_node> material;
  for (auto m : spec.child("Material").children("material")) material[m.attribute("name").value()] = m;
  const HyperelasticLaw soft = law_of(scene.materials["soft"]);
  EXPECT_STREQ(material["soft"].attribute("type").value(), "Mooney-Rivlin");
  EXPECT_DOUBLE_EQ(material["soft"].child("c1").text().as_double(), soft.shear_modulus_pa() / 2);
  EXPECT_EQ(material["soft"].child("c2").text().as_double(), 0.0);
  EXPECT_DOUBLE_EQ(material["soft"].child("k").text().as_double(), soft.bulk_modulus_pa);
  EXPECT_STREQ(material["soft"].child("pressure_model").text().get(), "Abaqus");
  EXPECT_STREQ(material["stiff"].attribute("type").value(), "isotropic elastic");
  EXPECT_EQ(material["stiff"].child("E").text().as_double(), 9000.0);
  EXPECT_EQ(material["stiff"].child("density").text().as_double(), 1100.0);
}

TEST_F(FebioExport, RefusesALatticeWithNoCell) {
  const Lattice lat = build_lattice(voxelise_shapes(test::box_scene(1, 1, 6, 0.002)));
  Scene scene;
  scene.materials["soft"] = test::material("soft", 3000);
  EXPECT_THROW(write_febio(path_, scene, lat, std::vector<bool>(lat.element_count(), false)), Error);
  EXPECT_FALSE(std::filesystem::exists(path_));
}

/// FEBio's uncoupled strain energy (Ogden: sum c_i/m_i^2 (sum lbar^m_i - 3); Mooney-Rivlin:
/// c1 (Ibar1 - 3) + c2 (Ibar2 - 3)) plus U(J) = k/2 (J - 1)^2 ("Abaqus"), from the written parameters.
double febio_energy(const FebioMaterial& m, const Eigen::Matrix3d& F) {
  std::map<std::string, double> p(m.parameters.begin(), m.parameters.end());
  const double J = F.determinant();
  const Eigen::Matrix3d Cbar = std::pow(J, -2.0 / 3.0) * F.transpose() * F;
  double W = p.at("k") / 2 * (J - 1) * (J - 1);
  if (m.type == "Mooney-Rivlin") {
    const double I1 = Cbar.trace(), I2 = 0.5 * (I1 * I1 - (Cbar * Cbar).trace());
    return W + p.at("c1") * (I1 - 3) + p.at("c2") * (I2 - 3);
  }
  const Eigen::Vector3d lambda2 = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(Cbar).eigenvalues();
  for (int i = 1; p.count("c" + std::to_string(i)); ++i) {
    const double c = p.at("c" + std::to_string(i)), mi = p.at("m" + std::to_string(i));
    double sum = 0;
    for (int k = 0; k < 3; ++k) sum += std::pow(lambda2[k], mi / 2);
    W += c / (mi * mi) * (sum - 3);
  }
  return W;
}

TEST(FebioMaterial, HyperelasticLawsKeepTheirStrainEnergy) {
  MaterialSpec mooney = test::material("mr", 0);
  mooney.law = "mooney-rivlin";
  mooney.c10_pa = 800;
  mooney.c01_pa = 200;
  mooney.bulk_modulus_pa = 40000;
  MaterialSpec ogden3 = test::validation_material("ogden", 0.49);
  ogden3.ogden_mu_pa = {1200, -300, 50};
  ogden3.ogden_alpha = {4, -2, 9};
  std::mt19937 gen(11);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  for (const MaterialSpec& spec : {test::validation_material("neo-hookean", 0.45), mooney,
                                   test::validation_material("ogden", 0.45), ogden3}) {
    const FebioMaterial m = febio_material(spec);
    EXPECT_TRUE(m.note.empty()) << spec.law;
    const HyperelasticLaw law = law_of(spec);
    for (int trial = 0; trial < 20; ++trial) {
      Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
      for (int k = 0; k < 9; ++k) F(k / 3, k % 3) += u(gen);
      if (F.determinant() < 0.3) continue;
      const double W = strain_energy(law, F);
      EXPECT_NEAR(febio_energy(m, F), W, 1e-9 * std::abs(W) + 1e-9) << spec.law << " trial " << trial;
    }
  }
}

TEST(FebioMaterial, SpringLawsSayHowTheyDiffer) {
  MaterialSpec biphasic = test::material("b", 5000);
  biphasic.law = "biphasic";
  for (const MaterialSpec& spec : {test::material("l", 5000), biphasic}) {
    const FebioMaterial m = febio_material(spec);
    EXPECT_EQ(m.type, "isotropic elastic");
    EXPECT_FALSE(m.note.empty());
  }
}

}  // namespace
}  // namespace vb
