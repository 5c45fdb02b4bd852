#include <gtest/gtest.h>

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <numbers>

#include "engine/error.hpp"
#include "engine/image/breast_phantom.hpp"

namespace vb {
namespace {

namespace lbl = phantom_label;

/// Phantoms by seed, built once: the read-only tests share them (each takes ~50 ms).
const Phantom& phantom_for_seed(std::uint64_t seed) {
  static std::map<std::uint64_t, Phantom> cache;
  auto it = cache.find(seed);
  if (it == cache.end()) {
    PhantomSpec spec;
    spec.seed = seed;
    it = cache.emplace(seed, make_breast_phantom(spec)).first;
  }
  return it->second;
}

/// A smaller breast, for the tests that need fine voxels.
PhantomSpec small_breast_spec(double spacing_m) {
  PhantomSpec spec;
  spec.spacing_m = spacing_m;
  spec.breast_radii_m = {0.04, 0.025, 0.035};
  spec.fov_margin_m = 0.006;
  spec.chest_wall_depth_m = 0.024;
  return spec;
}

int label_at(const Phantom& p, std::size_t n) { return int(p.labels.values[n]); }

bool is_breast_interior(int label) { return label == lbl::adipose || label == lbl::fibroglandular; }

bool bitwise_equal(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

struct LabelStats {
  std::size_t count = 0;
  double mean_hu = 0.0, sd_hu = 0.0;
};

LabelStats ct_stats(const Phantom& p, int label) {
  LabelStats s;
  double sum = 0.0, sum_sq = 0.0;
  for (std::size_t n = 0; n < p.ct.values.size(); ++n) {
    if (label_at(p, n) != label) continue;
    ++s.count;
    sum += p.ct.values[n];
    sum_sq += double(p.ct.values[n]) * p.ct.values[n];
  }
  if (s.count == 0) return s;
  s.mean_hu = sum / double(s.count);
  s.sd_hu = std::sqrt(std::max(0.0, sum_sq / double(s.count) - s.mean_hu * s.mean_hu));
  return s;
}

std::size_t label_count(const Phantom& p, int label) {
  return std::size_t(std::count(p.labels.values.begin(), p.labels.values.end(), float(label)));
}

/// Body voxels with an in-volume face neighbour of air that are not skin (should be none).
std::size_t unskinned_boundary_voxels(const Phantom& p) {
  const auto& d = p.labels.dims;
  const std::array<std::array<int, 3>, 6> faces{{{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}}};
  std::size_t bad = 0;
  for (int k = 0; k < d[2]; ++k)
    for (int j = 0; j < d[1]; ++j)
      for (int i = 0; i < d[0]; ++i) {
        const int label = label_at(p, p.labels.linear_index(i, j, k));
        if (label == lbl::air || label == lbl::skin) continue;
        for (const auto& f : faces) {
          const int a = i + f[0], b = j + f[1], c = k + f[2];
          if (a < 0 || b < 0 || c < 0 || a >= d[0] || b >= d[1] || c >= d[2]) continue;
          if (label_at(p, p.labels.linear_index(a, b, c)) == lbl::air) ++bad;
        }
      }
  return bad;
}

/// The vb::Error text thrown by fn ("" and a test failure when none is thrown).
template <class Fn>
std::string error_text(Fn&& fn) {
  try {
    fn();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a vb::Error";
  return {};
}

PhantomSpec spec_with_tumour(const std::string& type, Eigen::Vector3d center_m, double radius_m) {
  PhantomSpec spec;
  spec.tumours.push_back({type, center_m, radius_m});
  return spec;
}

// ---------------------------------------------------------------- determinism and geometry

TEST(BreastPhantom, SameSeedGivesBitIdenticalVolumes) {
  const Phantom again = make_breast_phantom(PhantomSpec{});
  const Phantom& first = phantom_for_seed(1);
  EXPECT_TRUE(bitwise_equal(first.ct.values, again.ct.values));
  EXPECT_TRUE(bitwise_equal(first.labels.values, again.labels.values));
  EXPECT_EQ(first.ct.affine_lps_m, again.ct.affine_lps_m);
}

TEST(BreastPhantom, DifferentSeedsChangeOnlyTheGlandularTexture) {
  const Phantom& a = phantom_for_seed(1);
  const Phantom& b = phantom_for_seed(2);
  ASSERT_EQ(a.labels.dims, b.labels.dims);
  std::size_t interior = 0, texture_changes = 0, geometry_changes = 0;
  for (std::size_t n = 0; n < a.labels.values.size(); ++n) {
    const int la = label_at(a, n), lb = label_at(b, n);
    if (is_breast_interior(la) != is_breast_interior(lb) || (!is_breast_interior(la) && la != lb))
      ++geometry_changes;
    if (is_breast_interior(la)) ++interior;
    if (is_breast_interior(la) && la != lb) ++texture_changes;
  }
  EXPECT_EQ(geometry_changes, 0u);
  EXPECT_GT(texture_changes, interior / 20) << "the glandular pattern should depend on the seed";
  EXPECT_FALSE(bitwise_equal(a.ct.values, b.ct.values));
}

TEST(BreastPhantom, GridIsAxisAlignedWithTheBreastCentredAtTheOrigin) {
  const Phantom& p = phantom_for_seed(1);
  const double h_m = PhantomSpec{}.spacing_m;
  EXPECT_EQ(p.ct.dims, p.labels.dims);
  EXPECT_EQ(p.ct.affine_lps_m, p.labels.affine_lps_m);
  EXPECT_EQ(p.ct.modality, "CT");
  EXPECT_EQ(p.labels.modality, "LABEL");
  const Eigen::Matrix3d axes_m = p.ct.affine_lps_m.topLeftCorner<3, 3>();
  EXPECT_TRUE(axes_m.isApprox(h_m * Eigen::Matrix3d::Identity()));
  EXPECT_EQ(p.ct.values.size(), p.ct.voxel_count());
  EXPECT_LE(p.ct.voxel_count(), 1'000'000u) << "keeps the stored sample small";

  // Breast centre at x = z = 0 on a voxel centre; a voxel plane at y = 0 (the chest-wall front).
  const Eigen::Vector3d first_m = p.ct.world_of_index(Eigen::Vector3d::Zero());
  const Eigen::Vector3d middle_m =
      p.ct.world_of_index(Eigen::Vector3d((p.ct.dims[0] - 1) / 2.0, 0.0, (p.ct.dims[2] - 1) / 2.0));
  EXPECT_NEAR(middle_m.x(), 0.0, 1e-12);
  EXPECT_NEAR(middle_m.z(), 0.0, 1e-12);
  EXPECT_NEAR(std::remainder(first_m.y(), h_m), 0.0, 1e-12);

  const std::vector<std::string> names{"air", "skin", "adipose", "fibroglandular", "muscle", "bone", "tumour"};
  EXPECT_EQ(p.label_names, names);
}

/// --dims and three spacings (a planning CT's field of view, scaled down): the grid has exactly
/// those dims and edges, the breast mound in front of the chest wall (y < 0) has the default
/// phantom's volume (to 2%: its edge texture is random) in the same place, the extra voxels in
/// front of it are air (the chest-wall slab spans the whole field, as in a CT), and dims too small
/// are refused naming the smallest that cover it.
TEST(BreastPhantom, DimsAndPerAxisSpacingPlaceTheSamePhantomInALargerField) {
  PhantomSpec base;
  base.spacing_m = 0.004;
  const Phantom small = make_breast_phantom(base);
  PhantomSpec spec = base;
  spec.spacing_xyz_m = Eigen::Vector3d(0.004, 0.004, 0.004);
  spec.dims = {small.ct.dims[0] + 10, small.ct.dims[1] + 6, small.ct.dims[2] + 4};
  const Phantom large = make_breast_phantom(spec);
  EXPECT_EQ(large.ct.dims, spec.dims);
  const Eigen::Matrix3d large_axes = large.ct.affine_lps_m.topLeftCorner<3, 3>();
  EXPECT_TRUE(large_axes.isApprox(0.004 * Eigen::Matrix3d::Identity()));
  std::size_t compared = 0, front_air = 0, front_outside = 0, body_small = 0, body_large = 0;
  for (int k = 0; k < large.labels.dims[2]; ++k)
    for (int j = 0; j < large.labels.dims[1]; ++j)
      for (int i = 0; i < large.labels.dims[0]; ++i) {
        const Eigen::Vector4d w = large.labels.affine_lps_m * Eigen::Vector4d(i, j, k, 1);
        if (w.y() >= 0) continue;  // the chest wall: it fills each field
        const Eigen::Vector4d h = small.labels.affine_lps_m.inverse() * w;
        const Eigen::Vector3i n(int(std::lround(h.x())), int(std::lround(h.y())), int(std::lround(h.z())));
        ASSERT_NEAR((h.head<3>() - n.cast<double>()).norm(), 0.0, 1e-9) << "voxel centres coincide";
        const bool inside = (n.array() >= 0).all() && n.x() < small.labels.dims[0] && n.y() < small.labels.dims[1] &&
                            n.z() < small.labels.dims[2];
        const float label = large.labels.values[large.labels.linear_index(i, j, k)];
        if (inside) {
          body_small += small.labels.values[small.labels.linear_index(n.x(), n.y(), n.z())] != 0.f;
          body_large += label != 0.f;
          ++compared;
        } else {
          ++front_outside;
          front_air += label == 0.f;
        }
      }
  EXPECT_GT(compared, small.labels.voxel_count() / 3);
  EXPECT_GT(body_small, 1000u);
  EXPECT_NEAR(double(body_large), double(body_small), 0.02 * double(body_small));
  EXPECT_GT(front_outside, 0u);
  EXPECT_EQ(front_air, front_outside);

  PhantomSpec planning = base;  // anisotropic: 2 × 2 × 5 mm
  planning.spacing_xyz_m = Eigen::Vector3d(0.002, 0.002, 0.005);
  const Phantom p = make_breast_phantom(planning);
  const Eigen::Matrix3d axes = p.ct.affine_lps_m.topLeftCorner<3, 3>();
  const Eigen::Matrix3d expected = Eigen::Vector3d(0.002, 0.002, 0.005).asDiagonal();
  EXPECT_TRUE(axes.isApprox(expected));
  PhantomSpec too_small = base;
  too_small.dims = {small.ct.dims[0] - 1, small.ct.dims[1], small.ct.dims[2]};
  const std::string error = error_text([&] { make_breast_phantom(too_small); });
  EXPECT_NE(error.find("do not cover the phantom: it needs at least " + std::to_string(small.ct.dims[0])),
            std::string::npos) << error;
}

TEST(BreastPhantom, BreastProtrudesAnteriorlyToItsDepth) {
  const Phantom& p = phantom_for_seed(1);
  const PhantomSpec spec;
  const int ci = (p.labels.dims[0] - 1) / 2, ck = (p.labels.dims[2] - 1) / 2;
  // Along the central ray the first body voxel from the front is the nipple skin, at y ≈ −depth.
  for (int j = 0; j < p.labels.dims[1]; ++j) {
    const int label = label_at(p, p.labels.linear_index(ci, j, ck));
    if (label == lbl::air) continue;
    EXPECT_EQ(label, lbl::skin);
    EXPECT_NEAR(p.labels.world_of_index(Eigen::Vector3d(ci, j, ck)).y(), -spec.breast_radii_m.y(),
                spec.spacing_m);
    return;
  }
  FAIL() << "no body voxel on the central ray";
}

// ---------------------------------------------------------------- tissue values

TEST(BreastPhantom, HuStatisticsPerLabelAreInTypicalBands) {
  const Phantom& p = phantom_for_seed(1);
  const LabelStats air = ct_stats(p, lbl::air), skin = ct_stats(p, lbl::skin),
                   adipose = ct_stats(p, lbl::adipose), gland = ct_stats(p, lbl::fibroglandular),
                   muscle = ct_stats(p, lbl::muscle), bone = ct_stats(p, lbl::bone);
  for (const LabelStats* s : {&air, &skin, &adipose, &gland, &muscle, &bone}) EXPECT_GT(s->count, 0u);
  EXPECT_EQ(label_count(p, lbl::tumour), 0u) << "no tumour unless requested";
  EXPECT_LT(air.mean_hu, -900.0);
  EXPECT_GE(skin.mean_hu, 20.0);
  EXPECT_LE(skin.mean_hu, 80.0);
  EXPECT_GE(adipose.mean_hu, -130.0);
  EXPECT_LE(adipose.mean_hu, -70.0);
  EXPECT_GE(gland.mean_hu, 0.0);
  EXPECT_LE(gland.mean_hu, 80.0);
  EXPECT_GE(muscle.mean_hu, 20.0);
  EXPECT_LE(muscle.mean_hu, 80.0);
  EXPECT_GT(bone.mean_hu, 200.0);
  EXPECT_NEAR(adipose.sd_hu, PhantomSpec{}.noise_sigma_hu, 1.0) << "image noise σ";
}

TEST(BreastPhantom, ZeroNoiseLeavesExactTissueValues) {
  PhantomSpec spec;
  spec.noise_sigma_hu = 0.0;
  const Phantom p = make_breast_phantom(spec);
  EXPECT_EQ(ct_stats(p, lbl::adipose).sd_hu, 0.0);
  EXPECT_EQ(ct_stats(p, lbl::adipose).mean_hu, -100.0);
  EXPECT_EQ(ct_stats(p, lbl::air).mean_hu, -1000.0);
}

TEST(BreastPhantom, GlandularTissueConcentratesBehindTheNipple) {
  const PhantomSpec spec;
  for (std::uint64_t seed : {1u, 2u}) {
    const Phantom& p = phantom_for_seed(seed);
    const double fraction = double(label_count(p, lbl::fibroglandular)) /
                            double(label_count(p, lbl::fibroglandular) + label_count(p, lbl::adipose));
    EXPECT_GT(fraction, 0.1) << "seed " << seed;
    EXPECT_LT(fraction, 0.5) << "seed " << seed;

    Eigen::Vector3d centroid_m = Eigen::Vector3d::Zero();
    for (int k = 0; k < p.labels.dims[2]; ++k)
      for (int j = 0; j < p.labels.dims[1]; ++j)
        for (int i = 0; i < p.labels.dims[0]; ++i)
          if (label_at(p, p.labels.linear_index(i, j, k)) == lbl::fibroglandular)
            centroid_m += p.labels.world_of_index(Eigen::Vector3d(i, j, k));
    centroid_m /= double(label_count(p, lbl::fibroglandular));
    EXPECT_LT(std::hypot(centroid_m.x(), centroid_m.z()), 0.015) << "seed " << seed;
    EXPECT_LT(centroid_m.y(), -0.2 * spec.breast_radii_m.y()) << "seed " << seed;
  }
}

// ---------------------------------------------------------------- skin

TEST(BreastPhantom, SkinIsAClosedLayer) {
  EXPECT_EQ(unskinned_boundary_voxels(phantom_for_seed(1)), 0u);
  EXPECT_EQ(unskinned_boundary_voxels(make_breast_phantom(small_breast_spec(0.0013))), 0u);
}

TEST(BreastPhantom, SkinThicknessFollowsTheSpecAtFineSpacing) {
  const PhantomSpec spec = small_breast_spec(0.001);
  const Phantom p = make_breast_phantom(spec);
  const int ci = (p.labels.dims[0] - 1) / 2, ck = (p.labels.dims[2] - 1) / 2;
  int skin_voxels_on_ray = 0;
  for (int j = 0; j < p.labels.dims[1] && label_at(p, p.labels.linear_index(ci, j, ck)) != lbl::muscle; ++j)
    skin_voxels_on_ray += label_at(p, p.labels.linear_index(ci, j, ck)) == lbl::skin;
  EXPECT_EQ(skin_voxels_on_ray, 2) << "2 mm of skin at the nipple in 1 mm voxels";
}

// ---------------------------------------------------------------- tumours

TEST(BreastPhantom, RequestedTumoursHaveTheirSphereVolumeAndHu) {
  PhantomSpec spec = spec_with_tumour("idc", {0.015, -0.025, 0.010}, 0.008);
  spec.tumours.push_back({"fibroadenoma", {-0.025, -0.015, -0.020}, 0.006});
  const Phantom p = make_breast_phantom(spec);
  const double voxel_m3 = std::pow(spec.spacing_m, 3);

  std::array<std::size_t, 2> voxels{0, 0};
  std::array<double, 2> hu_sum{0.0, 0.0};
  for (int k = 0; k < p.labels.dims[2]; ++k)
    for (int j = 0; j < p.labels.dims[1]; ++j)
      for (int i = 0; i < p.labels.dims[0]; ++i) {
        const std::size_t n = p.labels.linear_index(i, j, k);
        if (label_at(p, n) != lbl::tumour) continue;
        const Eigen::Vector3d x_m = p.labels.world_of_index(Eigen::Vector3d(i, j, k));
        const std::size_t which = (x_m - spec.tumours[0].center_m).norm() <= spec.tumours[0].radius_m ? 0 : 1;
        EXPECT_LE((x_m - spec.tumours[which].center_m).norm(), spec.tumours[which].radius_m);
        ++voxels[which];
        hu_sum[which] += p.ct.values[n];
      }
  const std::array<double, 2> expected_hu{60.0, 45.0};
  for (std::size_t t = 0; t < 2; ++t) {
    const double sphere_m3 = 4.0 / 3.0 * std::numbers::pi * std::pow(spec.tumours[t].radius_m, 3);
    EXPECT_NEAR(double(voxels[t]) * voxel_m3 / sphere_m3, 1.0, 0.1) << spec.tumours[t].type;
    EXPECT_NEAR(hu_sum[t] / double(voxels[t]), expected_hu[t], 3.0) << spec.tumours[t].type;
  }
}

TEST(BreastPhantom, TumoursLeaveTheRestOfTheAnatomyUnchanged) {
  const Phantom p = make_breast_phantom(spec_with_tumour("dcis", {0.0, -0.02, 0.0}, 0.005));
  const Phantom& plain = phantom_for_seed(1);
  std::size_t changed_outside = 0;  // tumours draw no random numbers, so noise is unchanged too
  for (std::size_t n = 0; n < p.labels.values.size(); ++n)
    if (label_at(p, n) != lbl::tumour &&
        (label_at(p, n) != label_at(plain, n) || p.ct.values[n] != plain.ct.values[n]))
      ++changed_outside;
  EXPECT_EQ(changed_outside, 0u);
  EXPECT_GT(label_count(p, lbl::tumour), 0u);
  EXPECT_NEAR(ct_stats(p, lbl::tumour).mean_hu, 50.0, 5.0);
}

// ---------------------------------------------------------------- invalid input

TEST(BreastPhantom, InvalidSpacingThrows) {
  for (double spacing_m : {0.0, -0.002, 0.011, std::nan("")}) {
    PhantomSpec spec;
    spec.spacing_m = spacing_m;
    EXPECT_NE(error_text([&] { make_breast_phantom(spec); }).find("spacing"), std::string::npos) << spacing_m;
  }
}

TEST(BreastPhantom, InvalidGeometryThrows) {
  PhantomSpec no_skin;
  no_skin.skin_thickness_m = 0.0;
  EXPECT_NE(error_text([&] { make_breast_phantom(no_skin); }).find("skin"), std::string::npos);
  PhantomSpec shallow_chest;
  shallow_chest.chest_wall_depth_m = 0.015;  // pectoral 10 mm + ribs 8 mm do not fit
  EXPECT_NE(error_text([&] { make_breast_phantom(shallow_chest); }).find("ribs"), std::string::npos);
}

TEST(BreastPhantom, InvalidTumourThrowsNamingIt) {
  const std::string zero_radius =
      error_text([] { make_breast_phantom(spec_with_tumour("idc", {0.0, -0.02, 0.0}, 0.0)); });
  EXPECT_NE(zero_radius.find("tumour #1 (idc)"), std::string::npos) << zero_radius;
  EXPECT_NE(zero_radius.find("radius"), std::string::npos) << zero_radius;

  for (const Eigen::Vector3d& outside_m :
       {Eigen::Vector3d(0.0, 0.01, 0.0), Eigen::Vector3d(0.09, -0.01, 0.0), Eigen::Vector3d(0.0, -0.05, 0.0)}) {
    PhantomSpec spec = spec_with_tumour("idc", {0.0, -0.02, 0.0}, 0.005);
    spec.tumours.push_back({"dcis", outside_m, 0.005});
    const std::string text = error_text([&] { make_breast_phantom(spec); });
    EXPECT_NE(text.find("tumour #2 (dcis)"), std::string::npos) << text;
    EXPECT_NE(text.find("outside the breast"), std::string::npos) << text;
  }

  const std::string unknown =
      error_text([] { make_breast_phantom(spec_with_tumour("lipoma", {0.0, -0.02, 0.0}, 0.005)); });
  for (const char* type : {"lipoma", "idc", "dcis", "fibroadenoma"})
    EXPECT_NE(unknown.find(type), std::string::npos) << unknown;
}

// ---------------------------------------------------------------- --tumour option

TEST(ParseTumourOption, ReadsMillimetresIntoMetres) {
  const PhantomTumour t = parse_tumour_option("idc,15,-25,10,8");
  EXPECT_EQ(t.type, "idc");
  EXPECT_NEAR(t.center_m.x(), 0.015, 1e-15);
  EXPECT_NEAR(t.center_m.y(), -0.025, 1e-15);
  EXPECT_NEAR(t.center_m.z(), 0.010, 1e-15);
  EXPECT_NEAR(t.radius_m, 0.008, 1e-15);

  const PhantomTumour spaced = parse_tumour_option(" fibroadenoma , -2.5, -30 ,0 , 6.5 ");
  EXPECT_EQ(spaced.type, "fibroadenoma");
  EXPECT_NEAR(spaced.center_m.x(), -0.0025, 1e-15);
  EXPECT_NEAR(spaced.radius_m, 0.0065, 1e-15);
}

TEST(ParseTumourOption, ErrorsNameTheBadField) {
  EXPECT_NE(error_text([] { parse_tumour_option("idc,15,-25,10"); }).find("5 comma-separated"), std::string::npos);
  EXPECT_NE(error_text([] { parse_tumour_option("idc,15,-25,10,8,1"); }).find("5 comma-separated"),
            std::string::npos);
  EXPECT_NE(error_text([] { parse_tumour_option("idc,15,abc,10,8"); }).find("field 'y'"), std::string::npos);
  EXPECT_NE(error_text([] { parse_tumour_option("idc,15mm,-25,10,8"); }).find("field 'x'"), std::string::npos);
  EXPECT_NE(error_text([] { parse_tumour_option("idc,15,-25,,8"); }).find("field 'z'"), std::string::npos);
  EXPECT_NE(error_text([] { parse_tumour_option("idc,15,-25,10,0"); }).find("field 'radius'"), std::string::npos);
  EXPECT_NE(error_text([] { parse_tumour_option("idc,15,-25,10,inf"); }).find("field 'radius'"),
            std::string::npos);
  const std::string unknown = error_text([] { parse_tumour_option("cyst,15,-25,10,8"); });
  EXPECT_NE(unknown.find("cyst"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("fibroadenoma"), std::string::npos) << unknown;
}

}  // namespace
}  // namespace vb
