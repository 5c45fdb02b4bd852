#include "engine/image/breast_phantom.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <numbers>
#include <random>
#include <sstream>
#include <string_view>

#include "engine/error.hpp"

namespace vb {
namespace {

namespace lbl = phantom_label;

// Typical unenhanced CT numbers; docs/PHANTOM.md lists the ranges they sit in.
constexpr double kAirHu = -1000.0;
constexpr double kSkinHu = 50.0;
constexpr double kAdiposeHu = -100.0;
constexpr double kFibroglandularHu = 40.0;
constexpr double kMuscleHu = 50.0;
constexpr double kCorticalBoneHu = 700.0;
constexpr double kMarrowBoneHu = 150.0;
constexpr double kCortexStartLevel = 0.8;  // rib level beyond which bone is cortical shell

struct TumourType {
  std::string_view name;
  double hu;
};
constexpr std::array<TumourType, 3> kTumourTypes{{{"idc", 60.0}, {"dcis", 50.0}, {"fibroadenoma", 45.0}}};

// Glandular texture: a retroareolar envelope modulated by random Gaussian blobs. Blob sizes are
// in metres, so a seed gives the same anatomy at every spacing.
constexpr std::size_t kGlandBlobCount = 800;
constexpr double kGlandBlobSigmaMin_m = 0.0025;
constexpr double kGlandBlobSigmaMax_m = 0.005;
constexpr double kGlandBlobWeightMax = 1.5;
constexpr double kGlandThreshold = 0.5;
constexpr double kGlandCentreDepthFraction = 0.45;  // of the breast depth: behind the nipple
constexpr double kGlandExtentFraction = 0.57;       // of each breast radius

// Keeps a phantom request from exhausting memory (two float volumes plus a copy).
constexpr double kMaxVoxels = 1.2e8;

// ---------------------------------------------------------------- formatting and validation

std::string mm_text(double metres) {
  std::ostringstream s;
  s << metres * 1e3 << " mm";
  return s.str();
}

std::string mm_text(const Eigen::Vector3d& metres) {
  std::ostringstream s;
  s << "(" << metres.x() * 1e3 << ", " << metres.y() * 1e3 << ", " << metres.z() * 1e3 << ") mm";
  return s.str();
}

bool positive(double v) { return std::isfinite(v) && v > 0.0; }

std::string tumour_type_list() {
  std::string s;
  for (const TumourType& t : kTumourTypes) s.append(s.empty() ? "" : ", ").append(t.name);
  return s;
}

const TumourType& tumour_type(std::string_view name, const std::string& where) {
  const auto it = std::find_if(kTumourTypes.begin(), kTumourTypes.end(),
                               [&](const TumourType& t) { return t.name == name; });
  if (it == kTumourTypes.end())
    throw Error("unknown tumour type '" + std::string(name) + "'", where, "one of: " + tumour_type_list());
  return *it;
}

// ---------------------------------------------------------------- anatomy (analytic, LPS m)

/// Σ(p/r)² over the breast radii: ≤ 1 inside the ellipsoid whose y < 0 half is the mound.
double breast_mound_level(const Eigen::Vector3d& p, const PhantomSpec& spec) {
  return (p.array() / spec.breast_radii_m.array()).square().sum();
}

bool in_breast_mound(const Eigen::Vector3d& p, const PhantomSpec& spec) {
  return p.y() < 0.0 && breast_mound_level(p, spec) <= 1.0;
}

/// Elliptic radius of p about the nearest rib axis: 0 on the axis, 1 on the bone surface. Ribs
/// run along x just behind the pectoral muscle, one every rib_pitch_m in z.
double rib_level(const Eigen::Vector3d& p, const PhantomSpec& spec) {
  const double dy_m = p.y() - (spec.pectoral_thickness_m + spec.rib_half_thickness_m);
  const double dz_m = p.z() - spec.rib_pitch_m * std::round(p.z() / spec.rib_pitch_m);
  return std::hypot(dy_m / spec.rib_half_thickness_m, dz_m / spec.rib_half_height_m);
}

/// Posterior to y = 0: ribs in muscle (pectoral in front, intercostal/chest-wall tissue around).
int chest_wall_label(const Eigen::Vector3d& p, const PhantomSpec& spec) {
  return rib_level(p, spec) <= 1.0 ? lbl::bone : lbl::muscle;
}

struct GlandBlob {
  Eigen::Vector3d center_m;
  double sigma_m;
  double weight;
};

/// [0, 1) from the generator's raw bits: std::uniform_real_distribution is implementation-defined,
/// which would break the seed contract across standard libraries.
double uniform01(std::mt19937_64& rng) { return double(rng() >> 11) * 0x1.0p-53; }

double uniform(std::mt19937_64& rng, double lo, double hi) { return lo + (hi - lo) * uniform01(rng); }

std::vector<GlandBlob> draw_gland_blobs(const PhantomSpec& spec, std::mt19937_64& rng) {
  const Eigen::Vector3d& r_m = spec.breast_radii_m;
  std::vector<GlandBlob> blobs;
  while (blobs.size() < kGlandBlobCount) {
    // One draw per statement: argument evaluation order is unspecified.
    const double x_m = uniform(rng, -r_m.x(), r_m.x());
    const double y_m = uniform(rng, -r_m.y(), 0.0);
    const double z_m = uniform(rng, -r_m.z(), r_m.z());
    const double sigma_m = uniform(rng, kGlandBlobSigmaMin_m, kGlandBlobSigmaMax_m);
    const double weight = uniform(rng, -kGlandBlobWeightMax, kGlandBlobWeightMax);
    const Eigen::Vector3d c_m(x_m, y_m, z_m);
    if (in_breast_mound(c_m, spec)) blobs.push_back({c_m, sigma_m, weight});
  }
  // Sorted by z so a voxel visits only the blobs that can reach it (blob_noise).
  std::stable_sort(blobs.begin(), blobs.end(),
                   [](const GlandBlob& a, const GlandBlob& b) { return a.center_m.z() < b.center_m.z(); });
  return blobs;
}

/// Smooth zero-mean texture: the sum of the blobs (each cut at 3σ, where it has fallen to 1.1%).
/// blobs are sorted by centre z.
double blob_noise(const Eigen::Vector3d& p, const std::vector<GlandBlob>& blobs) {
  const double reach_m = 3.0 * kGlandBlobSigmaMax_m;
  auto b = std::lower_bound(blobs.begin(), blobs.end(), p.z() - reach_m,
                            [](const GlandBlob& blob, double z_m) { return blob.center_m.z() < z_m; });
  double sum = 0.0;
  for (; b != blobs.end() && b->center_m.z() <= p.z() + reach_m; ++b) {
    const double d2_m2 = (p - b->center_m).squaredNorm();
    const double s2_m2 = b->sigma_m * b->sigma_m;
    if (d2_m2 < 9.0 * s2_m2) sum += b->weight * std::exp(-0.5 * d2_m2 / s2_m2);
  }
  return sum;
}

/// Glandular tissue concentrates behind the nipple: a Gaussian envelope there, modulated by the
/// blobs so the edge is irregular and fat is interspersed; near the skin the envelope vanishes,
/// leaving a subcutaneous fat layer.
bool is_glandular(const Eigen::Vector3d& p, const PhantomSpec& spec, const std::vector<GlandBlob>& blobs) {
  const Eigen::Vector3d centre_m(0.0, -kGlandCentreDepthFraction * spec.breast_radii_m.y(), 0.0);
  const Eigen::Vector3d extent_m = kGlandExtentFraction * spec.breast_radii_m;
  const double envelope = std::exp(-((p - centre_m).array() / extent_m.array()).square().sum());
  return envelope * (1.0 + blob_noise(p, blobs)) > kGlandThreshold;
}

/// Tissue of the analytic anatomy at p, before skin and tumours are painted.
int anatomy_label(const Eigen::Vector3d& p, const PhantomSpec& spec, const std::vector<GlandBlob>& blobs) {
  if (p.y() >= 0.0) return chest_wall_label(p, spec);
  if (!in_breast_mound(p, spec)) return lbl::air;
  return is_glandular(p, spec, blobs) ? lbl::fibroglandular : lbl::adipose;
}

/// The last tumour containing p, or nullptr.
const PhantomTumour* tumour_at(const Eigen::Vector3d& p, const std::vector<PhantomTumour>& tumours) {
  const PhantomTumour* found = nullptr;
  for (const PhantomTumour& t : tumours)
    if ((p - t.center_m).norm() <= t.radius_m) found = &t;
  return found;
}

// ---------------------------------------------------------------- validation

/// Voxel edges along x, y, z (m): spacing_xyz_m when set, else spacing_m on every axis.
Eigen::Vector3d voxel_edges_m(const PhantomSpec& spec) {
  return (spec.spacing_xyz_m.array() > 0).all() ? spec.spacing_xyz_m : Eigen::Vector3d::Constant(spec.spacing_m);
}

void validate_spacing(const PhantomSpec& spec) {
  const Eigen::Vector3d h_m = voxel_edges_m(spec);
  require(h_m.allFinite() && (h_m.array() > 0).all() && h_m.maxCoeff() <= 0.01,
          "spacing must be in (0, 10] mm, got " + mm_text(h_m), "phantom.spacing_m");
}

void validate_geometry(const PhantomSpec& spec) {
  const Eigen::Vector3d& r_m = spec.breast_radii_m;
  require(positive(r_m.x()) && positive(r_m.y()) && positive(r_m.z()),
          "breast radii must be positive, got " + mm_text(r_m), "phantom.breast_radii_m");
  require(positive(spec.skin_thickness_m) && spec.skin_thickness_m <= 0.25 * r_m.minCoeff(),
          "skin thickness must be positive and at most a quarter of the smallest breast radius, got " +
              mm_text(spec.skin_thickness_m),
          "phantom.skin_thickness_m");
  require(positive(spec.pectoral_thickness_m), "pectoral thickness must be positive",
          "phantom.pectoral_thickness_m");
  require(positive(spec.rib_half_thickness_m) && positive(spec.rib_half_height_m),
          "rib half-thickness and half-height must be positive", "phantom.rib_half_thickness_m");
  require(std::isfinite(spec.chest_wall_depth_m) &&
              spec.pectoral_thickness_m + 2.0 * spec.rib_half_thickness_m <= spec.chest_wall_depth_m,
          "the pectoral muscle and the ribs behind it must fit in the chest wall slab, got depth " +
              mm_text(spec.chest_wall_depth_m),
          "phantom.chest_wall_depth_m", "pectoral_thickness_m + 2·rib_half_thickness_m ≤ chest_wall_depth_m");
  require(positive(spec.rib_pitch_m) && spec.rib_pitch_m > 2.0 * spec.rib_half_height_m,
          "rib pitch must exceed the rib height so ribs stay apart", "phantom.rib_pitch_m");
  require(std::isfinite(spec.fov_margin_m) && spec.fov_margin_m >= voxel_edges_m(spec).maxCoeff(),
          "field-of-view margin must be at least one voxel (air must surround the breast)",
          "phantom.fov_margin_m");
  require(std::isfinite(spec.noise_sigma_hu) && spec.noise_sigma_hu >= 0.0,
          "noise sigma must be finite and non-negative", "phantom.noise_sigma_hu");
}

void validate_tumour(const PhantomTumour& t, std::size_t index, const PhantomSpec& spec) {
  const std::string where = "tumour #" + std::to_string(index + 1) + " (" + t.type + ")";
  tumour_type(t.type, where);
  require(positive(t.radius_m), "radius must be positive, got " + mm_text(t.radius_m), where);
  require(t.center_m.allFinite() && in_breast_mound(t.center_m, spec),
          "centre " + mm_text(t.center_m) + " lies outside the breast mound", where,
          "the mound is y < 0 inside the ellipsoid of radii " + mm_text(spec.breast_radii_m) +
              " centred at the origin");
}

void validate_spec(const PhantomSpec& spec) {
  validate_spacing(spec);
  validate_geometry(spec);
  for (std::size_t n = 0; n < spec.tumours.size(); ++n) validate_tumour(spec.tumours[n], n, spec);
}

// ---------------------------------------------------------------- the voxel grid

int voxels_covering(double length_m, double spacing_m) {
  return int(std::ceil(length_m / spacing_m - 1e-9));
}

/// Axis-aligned grid: breast centre on a voxel centre at x = z = 0, a voxel plane at y = 0.
ImageVolume make_grid(const PhantomSpec& spec, std::string modality) {
  const Eigen::Vector3d h_m = voxel_edges_m(spec);
  // Voxels from the breast centre to the field's edges: −x, +x, anterior (−y), posterior, −z, +z.
  int half_x = voxels_covering(spec.breast_radii_m.x() + spec.fov_margin_m, h_m.x());
  int half_z = voxels_covering(spec.breast_radii_m.z() + spec.fov_margin_m, h_m.z());
  int anterior = voxels_covering(spec.breast_radii_m.y() + spec.fov_margin_m, h_m.y());
  int posterior = voxels_covering(spec.chest_wall_depth_m, h_m.y());
  ImageVolume vol;
  vol.dims = {2 * half_x + 1, anterior + posterior + 1, 2 * half_z + 1};
  std::array<int, 3> low = {half_x, anterior, half_z};  // the index of the breast centre
  if (std::all_of(spec.dims.begin(), spec.dims.end(), [](int n) { return n > 0; })) {
    for (int a = 0; a < 3; ++a)
      require(spec.dims[a] >= vol.dims[a],
              "dims " + std::to_string(spec.dims[0]) + " × " + std::to_string(spec.dims[1]) + " × " +
                  std::to_string(spec.dims[2]) + " do not cover the phantom: it needs at least " +
                  std::to_string(vol.dims[0]) + " × " + std::to_string(vol.dims[1]) + " × " +
                  std::to_string(vol.dims[2]) + " voxels at this spacing",
              "phantom.dims", "give more voxels or a larger spacing");
    // The extra voxels split evenly on both sides of what the phantom needs.
    for (int a = 0; a < 3; ++a) low[a] += (spec.dims[a] - vol.dims[a]) / 2;
    vol.dims = spec.dims;
  }
  const double voxels = double(vol.dims[0]) * vol.dims[1] * vol.dims[2];
  require(voxels <= kMaxVoxels, "the phantom would have " + std::to_string(long(voxels)) + " voxels",
          "phantom.spacing_m", "increase the spacing or shrink the field of view");
  vol.affine_lps_m.topLeftCorner<3, 3>() = Eigen::Matrix3d(h_m.asDiagonal());
  vol.affine_lps_m.topRightCorner<3, 1>() = -h_m.cwiseProduct(Eigen::Vector3d(low[0], low[1], low[2]));
  vol.values.assign(vol.voxel_count(), 0.0f);
  vol.modality = std::move(modality);
  return vol;
}

/// Calls fn(ijk, linear index) for every voxel in storage order (i fastest).
template <class Fn>
void for_each_voxel(const ImageVolume& vol, Fn&& fn) {
  std::size_t n = 0;
  for (int k = 0; k < vol.dims[2]; ++k)
    for (int j = 0; j < vol.dims[1]; ++j)
      for (int i = 0; i < vol.dims[0]; ++i) fn(Eigen::Vector3i(i, j, k), n++);
}

Eigen::Vector3d centre_of(const ImageVolume& vol, const Eigen::Vector3i& ijk) {
  return vol.world_of_index(ijk.cast<double>());
}

bool inside(const ImageVolume& vol, const Eigen::Vector3i& ijk) {
  return (ijk.array() >= 0).all() && ijk.x() < vol.dims[0] && ijk.y() < vol.dims[1] && ijk.z() < vol.dims[2];
}

std::size_t index_of(const ImageVolume& vol, const Eigen::Vector3i& ijk) {
  return vol.linear_index(ijk.x(), ijk.y(), ijk.z());
}

bool is_air(float label) { return label == float(lbl::air); }

bool is_soft_tissue(float label) {
  return label == float(lbl::adipose) || label == float(lbl::fibroglandular) || label == float(lbl::muscle);
}

/// Integer offsets within the ellipsoid of semi-axes radius_vox (in voxels along i, j, k) of the
/// origin (the origin included).
std::vector<Eigen::Vector3i> ball_offsets(const Eigen::Vector3d& radius_vox) {
  const Eigen::Vector3i reach = (radius_vox.array() + 1e-9).floor().cast<int>().matrix();
  std::vector<Eigen::Vector3i> offsets;
  for (int c = -reach.z(); c <= reach.z(); ++c)
    for (int b = -reach.y(); b <= reach.y(); ++b)
      for (int a = -reach.x(); a <= reach.x(); ++a)
        if (Eigen::Vector3d(a, b, c).cwiseQuotient(radius_vox).squaredNorm() <= 1 + 1e-9) offsets.emplace_back(a, b, c);
  return offsets;
}

bool touches_body(const ImageVolume& labels, const Eigen::Vector3i& ijk) {
  static const std::array<Eigen::Vector3i, 6> kFaceOffsets{
      Eigen::Vector3i(1, 0, 0), Eigen::Vector3i(-1, 0, 0), Eigen::Vector3i(0, 1, 0),
      Eigen::Vector3i(0, -1, 0), Eigen::Vector3i(0, 0, 1), Eigen::Vector3i(0, 0, -1)};
  return std::any_of(kFaceOffsets.begin(), kFaceOffsets.end(), [&](const Eigen::Vector3i& o) {
    return inside(labels, ijk + o) && !is_air(labels.values[index_of(labels, ijk + o)]);
  });
}

// ---------------------------------------------------------------- painting the label map

void paint_anatomy(ImageVolume& labels, const PhantomSpec& spec, const std::vector<GlandBlob>& blobs) {
  for_each_voxel(labels, [&](const Eigen::Vector3i& ijk, std::size_t n) {
    labels.values[n] = float(anatomy_label(centre_of(labels, ijk), spec, blobs));
  });
}

/// Every body voxel within the skin thickness (and at least one voxel along each axis) of air
/// becomes skin, so the skin closes over the breast and the chest-wall front at any spacing. Only
/// air voxels on the body's edge are visited: the nearest air voxel to any body voxel is one of them.
void paint_skin(ImageVolume& labels, double skin_thickness_m) {
  const Eigen::Vector3d h_m = labels.spacing_m();
  const std::vector<Eigen::Vector3i> ball =
      ball_offsets(h_m.cwiseMax(Eigen::Vector3d::Constant(skin_thickness_m)).cwiseQuotient(h_m));
  const ImageVolume anatomy = labels;  // body membership before skin is painted
  for_each_voxel(anatomy, [&](const Eigen::Vector3i& ijk, std::size_t n) {
    if (!is_air(anatomy.values[n]) || !touches_body(anatomy, ijk)) return;
    for (const Eigen::Vector3i& o : ball) {
      const Eigen::Vector3i q = ijk + o;
      if (inside(anatomy, q) && !is_air(anatomy.values[index_of(anatomy, q)]))
        labels.values[index_of(labels, q)] = float(lbl::skin);
    }
  });
}

/// Tumours replace soft tissue only: skin and ribs keep their labels where a sphere reaches them.
void paint_tumours(ImageVolume& labels, const std::vector<PhantomTumour>& tumours) {
  if (tumours.empty()) return;
  for_each_voxel(labels, [&](const Eigen::Vector3i& ijk, std::size_t n) {
    if (is_soft_tissue(labels.values[n]) && tumour_at(centre_of(labels, ijk), tumours))
      labels.values[n] = float(lbl::tumour);
  });
}

// ---------------------------------------------------------------- the CT

/// Standard normal deviates by Box–Muller on raw generator bits (std::normal_distribution is
/// implementation-defined); deviates come in pairs, the second kept for the next call.
class NormalSource {
 public:
  explicit NormalSource(std::mt19937_64& rng) : rng_(rng) {}
  double next() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double radius = std::sqrt(-2.0 * std::log(1.0 - uniform01(rng_)));  // 1 − u avoids log(0)
    const double angle = 2.0 * std::numbers::pi * uniform01(rng_);
    spare_ = radius * std::sin(angle);
    has_spare_ = true;
    return radius * std::cos(angle);
  }

 private:
  std::mt19937_64& rng_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

double tissue_hu(int label, const Eigen::Vector3d& p, const PhantomSpec& spec) {
  switch (label) {
    case lbl::skin: return kSkinHu;
    case lbl::adipose: return kAdiposeHu;
    case lbl::fibroglandular: return kFibroglandularHu;
    case lbl::muscle: return kMuscleHu;
    case lbl::bone: return rib_level(p, spec) >= kCortexStartLevel ? kCorticalBoneHu : kMarrowBoneHu;
    case lbl::tumour: return tumour_type(tumour_at(p, spec.tumours)->type, "tumour").hu;
    default: return kAirHu;
  }
}

ImageVolume synthesize_ct(const ImageVolume& labels, const PhantomSpec& spec, std::mt19937_64& rng) {
  ImageVolume ct = labels;
  ct.modality = "CT";
  NormalSource normal(rng);
  for_each_voxel(ct, [&](const Eigen::Vector3i& ijk, std::size_t n) {
    const double hu = tissue_hu(int(labels.values[n]), centre_of(ct, ijk), spec);
    ct.values[n] = float(hu + spec.noise_sigma_hu * normal.next());
  });
  return ct;
}

// ---------------------------------------------------------------- option parsing

std::string_view trimmed(std::string_view s) {
  const auto first = s.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  return s.substr(first, s.find_last_not_of(" \t") - first + 1);
}

std::vector<std::string_view> split_fields(std::string_view text, char separator) {
  std::vector<std::string_view> fields;
  for (std::size_t start = 0;;) {
    const std::size_t end = text.find(separator, start);
    fields.push_back(trimmed(text.substr(start, end - start)));
    if (end == std::string_view::npos) return fields;
    start = end + 1;
  }
}

double parse_mm_field(std::string_view field, const std::string& name, const std::string& where) {
  double value_mm = 0.0;
  const auto [end, ec] = std::from_chars(field.data(), field.data() + field.size(), value_mm);
  require(!field.empty() && ec == std::errc() && end == field.data() + field.size() && std::isfinite(value_mm),
          "field '" + name + "' is not a number: '" + std::string(field) + "'", where,
          "lengths are in millimetres, e.g. idc,15,-25,10,8");
  return value_mm * 1e-3;
}

}  // namespace

Phantom make_breast_phantom(const PhantomSpec& spec) {
  validate_spec(spec);
  std::mt19937_64 rng(spec.seed);  // draws, in order: gland blobs, then image noise voxel by voxel
  const std::vector<GlandBlob> blobs = draw_gland_blobs(spec, rng);

  Phantom phantom;
  phantom.labels = make_grid(spec, "LABEL");
  paint_anatomy(phantom.labels, spec, blobs);
  paint_skin(phantom.labels, spec.skin_thickness_m);
  paint_tumours(phantom.labels, spec.tumours);
  phantom.ct = synthesize_ct(phantom.labels, spec, rng);
  phantom.label_names = {"air", "skin", "adipose", "fibroglandular", "muscle", "bone", "tumour"};
  return phantom;
}

PhantomTumour parse_tumour_option(const std::string& text) {
  const std::string where = "--tumour " + text;
  const std::vector<std::string_view> fields = split_fields(text, ',');
  require(fields.size() == 5,
          "expected 5 comma-separated fields type,x,y,z,radius, got " + std::to_string(fields.size()), where,
          "lengths in millimetres (LPS), e.g. idc,15,-25,10,8");
  PhantomTumour t;
  t.type = std::string(fields[0]);
  tumour_type(t.type, where);
  const std::array<std::string, 3> axis_names{"x", "y", "z"};
  for (int a = 0; a < 3; ++a) t.center_m[a] = parse_mm_field(fields[1 + a], axis_names[a], where);
  t.radius_m = parse_mm_field(fields[4], "radius", where);
  require(t.radius_m > 0.0, "field 'radius' must be positive, got " + mm_text(t.radius_m), where);
  return t;
}

}  // namespace vb
