#include "io/nifti_io.hpp"

#include <nifti/nifti2_io.h>

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <system_error>
#include <type_traits>
#include <vector>

#include "engine/error.hpp"
#include "io/atomic_file.hpp"

namespace vb {
namespace {

// ---- nifti_clib plumbing ---------------------------------------------------------------------

struct NiftiFree {
  void operator()(nifti_image* nim) const { nifti_image_free(nim); }
};
using NiftiPtr = std::unique_ptr<nifti_image, NiftiFree>;

/// nifti_clib prints its own diagnostics to stderr; ours (vb::Error) say more, so silence it.
void quiet_nifti_clib() {
  static const bool quiet = (nifti_set_debug_level(0), true);
  (void)quiet;
}

constexpr std::size_t kVectorComponents = 3;
constexpr double kMetresPerMm = 1e-3;
/// NIfTI-1 header (348 bytes) + the 4-byte extension flag: where the voxels start.
constexpr int kNifti1DataOffset = 352;

/// Sign of each vector component between LPS and RAS (either way).
constexpr std::array<double, 3> kLpsRasSign{-1.0, -1.0, 1.0};

/// Flips x and y: RAS <-> LPS (its own inverse).
const Eigen::Matrix4d& ras_lps_flip() {
  static const Eigen::Matrix4d flip = Eigen::Vector4d(-1, -1, 1, 1).asDiagonal();
  return flip;
}

Eigen::Matrix4d to_eigen(const nifti_dmat44& m) {
  Eigen::Matrix4d out;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out(r, c) = m.m[r][c];
  return out;
}

nifti_dmat44 to_nifti(const Eigen::Matrix4d& m) {
  nifti_dmat44 out;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out.m[r][c] = m(r, c);
  return out;
}

/// Calls f(T{}) with the C type of a supported NIfTI datatype; false when unsupported.
template <class F>
bool with_voxel_type(int datatype, F&& f) {
  switch (datatype) {
    case NIFTI_TYPE_INT8: f(std::int8_t{}); return true;
    case NIFTI_TYPE_UINT8: f(std::uint8_t{}); return true;
    case NIFTI_TYPE_INT16: f(std::int16_t{}); return true;
    case NIFTI_TYPE_UINT16: f(std::uint16_t{}); return true;
    case NIFTI_TYPE_INT32: f(std::int32_t{}); return true;
    case NIFTI_TYPE_UINT32: f(std::uint32_t{}); return true;
    case NIFTI_TYPE_FLOAT32: f(float{}); return true;
    case NIFTI_TYPE_FLOAT64: f(double{}); return true;
    default: return false;
  }
}

// ---- geometry checks (shared by reading and writing) -----------------------------------------

/// The affine must map voxels to a 3-D world: finite, positive spacing, axes not coplanar.
void check_affine(const Eigen::Matrix4d& affine_lps_m, const std::string& where) {
  require(affine_lps_m.allFinite(), "the voxel-to-world affine is not finite", where);
  const Eigen::Matrix3d axes = affine_lps_m.topLeftCorner<3, 3>();
  const Eigen::Vector3d spacing = axes.colwise().norm();
  require(spacing.minCoeff() > 0.0, "zero voxel spacing in the voxel-to-world affine", where);
  // Relative to the box volume so the test does not depend on the unit or the voxel size.
  require(std::abs(axes.determinant()) > 1e-6 * spacing.prod(),
          "the voxel-to-world affine is singular (voxel axes are coplanar)", where);
}

void check_dims(const std::array<int, 3>& dims, const std::string& where) {
  for (int n : dims)
    require(n >= 1 && n <= std::numeric_limits<std::int16_t>::max(),
            "grid size " + std::to_string(n) + " cannot be stored in NIfTI-1 (1..32767)", where);
}

std::string voxel_name(const std::array<int, 3>& dims, std::size_t index) {
  const std::size_t nx = std::size_t(dims[0]), ny = std::size_t(dims[1]);
  return "voxel (" + std::to_string(index % nx) + ", " + std::to_string(index / nx % ny) + ", " +
         std::to_string(index / (nx * ny)) + ")";
}

// ---- reading ---------------------------------------------------------------------------------

NiftiPtr open_header(const std::string& path) {
  quiet_nifti_clib();
  std::error_code ec;
  require(std::filesystem::exists(path, ec), "file not found", path);
  require(std::filesystem::is_regular_file(path, ec), "not a regular file", path);
  NiftiPtr nim(nifti_image_read(path.c_str(), /*read_data=*/0));
  require(nim != nullptr, "not a readable NIfTI file (bad or truncated header)", path,
          "check that the file is a complete .nii or .nii.gz file");
  require(nim->nifti_type != NIFTI_FTYPE_ANALYZE, "ANALYZE 7.5 file: it has no defined orientation",
          path, "convert it to NIfTI");
  require(with_voxel_type(nim->datatype, [](auto) {}),
          std::string("unsupported voxel type ") + nifti_datatype_string(nim->datatype), path,
          "use int8/16/32, uint8/16/32, float32 or float64");
  return nim;
}

/// Loads the voxels after the header has been accepted; a short read is a truncated file.
void load_voxels(nifti_image& nim, const std::string& path) {
  require(nifti_image_load(&nim) >= 0 && nim.data != nullptr, "voxel data missing or truncated",
          path, "the file is incomplete or corrupt; write or download it again");
}

/// dim[5..7] must be 1 except as listed; dim[4] (time) must be 1.
void check_extra_dims(const nifti_image& nim, int components, const std::string& path) {
  const std::array<std::int64_t, 4> expected{1, components, 1, 1};  // dim[4..7]
  for (int d = 4; d <= 7; ++d) {
    const std::int64_t n = d <= nim.dim[0] ? nim.dim[d] : 1;
    require(n == expected[std::size_t(d - 4)],
            "dim[" + std::to_string(d) + "] = " + std::to_string(n) + ", expected " +
                std::to_string(expected[std::size_t(d - 4)]) +
                (components == 1 ? " (only 3-D scalar images are read)"
                                 : " (a displacement field is (nx, ny, nz, 1, 3))"),
            path);
  }
}

double metres_per_unit(const nifti_image& nim, const std::string& path) {
  switch (nim.xyz_units) {
    case NIFTI_UNITS_METER: return 1.0;
    case NIFTI_UNITS_UNKNOWN:  // the usual reading of a missing unit (nibabel, ITK): mm
    case NIFTI_UNITS_MM: return kMetresPerMm;
    case NIFTI_UNITS_MICRON: return 1e-6;
    default:
      throw Error("unknown spatial unit code " + std::to_string(nim.xyz_units), path,
                  "xyzt_units must say m, mm or micron");
  }
}

/// pixdim[1..3] as stored: nifti_image's copy has zeros already replaced by 1.
std::array<double, 3> stored_pixdim(const std::string& path) {
  int version = 0;
  const std::unique_ptr<void, void (*)(void*)> header(
      nifti_read_header(path.c_str(), &version, /*check=*/0), std::free);
  require(header != nullptr && (version == 1 || version == 2), "cannot read the NIfTI header",
          path);
  const auto pixdim = [&](auto* h) {
    if (h->sizeof_hdr != int(sizeof *h)) swap_nifti_header(h, version);  // other byte order
    return std::array<double, 3>{h->pixdim[1], h->pixdim[2], h->pixdim[3]};
  };
  return version == 1 ? pixdim(static_cast<nifti_1_header*>(header.get()))
                      : pixdim(static_cast<nifti_2_header*>(header.get()));
}

/// The qform and the bare-pixdim fallback take the spacing from pixdim.
void check_pixdim(const std::string& path) {
  const std::array<double, 3> pixdim = stored_pixdim(path);
  for (std::size_t d = 0; d < 3; ++d)
    require(std::isfinite(pixdim[d]) && pixdim[d] > 0.0,
            "voxel spacing pixdim[" + std::to_string(d + 1) + "] = " + std::to_string(pixdim[d]) +
                " is not positive",
            path);
}

/// Voxel index -> file world (RAS, file unit): sform, else qform, else diag(pixdim).
Eigen::Matrix4d file_affine(const nifti_image& nim, const std::string& path) {
  if (nim.sform_code > 0) return to_eigen(nim.sto_xyz);
  check_pixdim(path);
  if (nim.qform_code > 0) return to_eigen(nim.qto_xyz);
  return Eigen::Vector4d(nim.pixdim[1], nim.pixdim[2], nim.pixdim[3], 1.0).asDiagonal();
}

/// Dims and the LPS-metre affine; values left empty.
ImageVolume read_grid(const nifti_image& nim, const std::string& path) {
  ImageVolume grid;
  for (int d = 0; d < 3; ++d) {
    const std::int64_t n = d < nim.dim[0] ? nim.dim[d + 1] : 1;
    require(
        n >= 1 && n <= std::numeric_limits<int>::max(),
        "grid size dim[" + std::to_string(d + 1) + "] = " + std::to_string(n) + " not supported",
        path);
    grid.dims[std::size_t(d)] = int(n);
  }
  grid.affine_lps_m = ras_lps_flip() * file_affine(nim, path);
  grid.affine_lps_m.topRows<3>() *= metres_per_unit(nim, path);
  check_affine(grid.affine_lps_m, path);
  return grid;
}

/// All nvox stored values as float, file order, scl_slope/scl_inter applied (in double).
std::vector<float> scaled_values(const nifti_image& nim) {
  const bool scaled = std::isfinite(nim.scl_slope) && nim.scl_slope != 0.0;
  const double slope = scaled ? nim.scl_slope : 1.0;
  const double inter = scaled && std::isfinite(nim.scl_inter) ? nim.scl_inter : 0.0;
  std::vector<float> out(std::size_t(nim.nvox));
  with_voxel_type(nim.datatype, [&](auto tag) {
    const auto* raw = static_cast<const decltype(tag)*>(nim.data);
    for (std::size_t i = 0; i < out.size(); ++i)
      out[i] = static_cast<float>(static_cast<double>(raw[i]) * slope + inter);
  });
  return out;
}

/// Header checked, grid built, voxels loaded: the common part of both readers.
struct LoadedNifti {
  NiftiPtr nim;
  ImageVolume grid;
};

LoadedNifti load(const std::string& path, int components) {
  LoadedNifti file{open_header(path), {}};
  check_extra_dims(*file.nim, components, path);
  file.grid = read_grid(*file.nim, path);
  load_voxels(*file.nim, path);
  return file;
}

// ---- writing ---------------------------------------------------------------------------------

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

bool gzip_for(const std::string& path) {
  if (ends_with(path, ".nii.gz")) return true;
  require(ends_with(path, ".nii"), "unsupported file name extension", path,
          "NIfTI files are written as .nii or .nii.gz");
  return false;
}

/// A NIfTI-1 image with zeroed voxels: (nx, ny, nz) or, with 3 components, (nx, ny, nz, 1, 3).
NiftiPtr new_image(const std::array<int, 3>& dims, int components, int datatype,
                   const std::string& path) {
  quiet_nifti_clib();
  check_dims(dims, path);
  const std::int64_t dim[8] = {
      components == 1 ? 3 : 5, dims[0], dims[1], dims[2], 1, components, 1, 1};
  NiftiPtr nim(nifti_make_new_nim(dim, datatype, /*data_fill=*/1));
  require(nim != nullptr && nim->data != nullptr, "cannot allocate the NIfTI image", path);
  nim->nifti_type = NIFTI_FTYPE_NIFTI1_1;
  nim->scl_slope = 1.0;  // stored values are the values
  nim->scl_inter = 0.0;
  return nim;
}

/// sform and qform (both code 1, scanner) and pixdim from the LPS-metre affine.
void set_geometry(nifti_image& nim, const Eigen::Matrix4d& affine_lps_m, const std::string& path) {
  check_affine(affine_lps_m, path);
  Eigen::Matrix4d ras_mm = ras_lps_flip() * affine_lps_m;
  ras_mm.topRows<3>() /= kMetresPerMm;
  nim.sform_code = nim.qform_code = NIFTI_XFORM_SCANNER_ANAT;
  nim.sto_xyz = to_nifti(ras_mm);
  nim.sto_ijk = nifti_dmat44_inverse(nim.sto_xyz);
  // The quaternion keeps the rotation part (polar decomposition) and the column norms.
  nifti_dmat44_to_quatern(nim.sto_xyz, &nim.quatern_b, &nim.quatern_c, &nim.quatern_d,
                          &nim.qoffset_x, &nim.qoffset_y, &nim.qoffset_z, &nim.pixdim[1],
                          &nim.pixdim[2], &nim.pixdim[3], &nim.qfac);
  nim.pixdim[0] = nim.qfac;
  nim.qto_xyz = nifti_quatern_to_dmat44(nim.quatern_b, nim.quatern_c, nim.quatern_d, nim.qoffset_x,
                                        nim.qoffset_y, nim.qoffset_z, nim.pixdim[1], nim.pixdim[2],
                                        nim.pixdim[3], nim.qfac);
  nim.qto_ijk = nifti_dmat44_inverse(nim.qto_xyz);
  nim.xyz_units = NIFTI_UNITS_MM;
  nifti_update_dims_from_array(&nim);  // copies pixdim[] into dx, dy, dz
}

void set_text(char* field, std::size_t size, const std::string& text) {
  text.copy(field, size - 1);
  field[std::min(text.size(), size - 1)] = '\0';
}

/// Header, extension flag, voxels through znzlib (gzip or not) into an atomic temporary file.
void write_file(const std::string& path, nifti_image& nim) {
  const bool gzip = gzip_for(path);
  nim.iname_offset = kNifti1DataOffset;
  nifti_1_header header{};
  require(nifti_convert_nim2n1hdr(&nim, &header) == 0, "cannot build the NIfTI-1 header", path);

  AtomicOutput out(path);
  znzFile file = znzopen(out.temp_path().c_str(), "wb", gzip ? 1 : 0);
  require(!znz_isnull(file), "cannot create file", path, "check the folder and its permissions");
  const char no_extension[4] = {0, 0, 0, 0};
  const std::size_t bytes = std::size_t(nim.nvox) * std::size_t(nim.nbyper);
  bool ok = znzwrite(&header, sizeof header, 1, file) == 1 &&
            znzwrite(no_extension, 1, sizeof no_extension, file) == sizeof no_extension &&
            znzwrite(nim.data, 1, bytes, file) == bytes;
  ok = znzclose(file) == 0 && ok;  // closing flushes (and finishes the gzip stream)
  require(ok, "cannot write file", path, "check free disk space");
  out.commit();
}

/// Rounds to nearest for integer types; refuses what the type cannot hold.
template <class T>
T stored_value(float value, const std::array<int, 3>& dims, std::size_t index,
               const std::string& path) {
  if constexpr (std::is_floating_point_v<T>) {
    return static_cast<T>(value);
  } else {
    const double rounded = std::round(double(value));
    require(std::isfinite(rounded) && rounded >= double(std::numeric_limits<T>::lowest()) &&
                rounded <= double(std::numeric_limits<T>::max()),
            "value " + std::to_string(value) + " at " + voxel_name(dims, index) +
                " does not fit the output voxel type",
            path, "write float32, or clamp the image first");
    return static_cast<T>(rounded);
  }
}

int datatype_of(NiftiType type) {
  switch (type) {
    case NiftiType::Int16: return NIFTI_TYPE_INT16;
    case NiftiType::UInt8: return NIFTI_TYPE_UINT8;
    case NiftiType::Float32: return NIFTI_TYPE_FLOAT32;
  }
  throw Error("unknown NiftiType");
}

}  // namespace

// ---- public API --------------------------------------------------------------------------------

ImageVolume read_nifti(const std::string& path) {
  LoadedNifti file = load(path, 1);
  file.grid.values = scaled_values(*file.nim);
  file.grid.modality = file.nim->intent_code == NIFTI_INTENT_LABEL ? "LABEL" : "";
  return std::move(file.grid);
}

void write_nifti(const std::string& path, const ImageVolume& image, NiftiType type) {
  require(image.values.size() == image.voxel_count(),
          "image has " + std::to_string(image.values.size()) + " values for " +
              std::to_string(image.voxel_count()) + " voxels",
          path);
  NiftiPtr nim = new_image(image.dims, 1, datatype_of(type), path);
  set_geometry(*nim, image.affine_lps_m, path);
  if (image.modality == "LABEL") nim->intent_code = NIFTI_INTENT_LABEL;
  set_text(nim->descrip, sizeof nim->descrip,
           image.modality.empty() ? "VoxBreast" : "VoxBreast " + image.modality);
  with_voxel_type(nim->datatype, [&](auto tag) {
    using T = decltype(tag);
    auto* out = static_cast<T*>(nim->data);
    for (std::size_t i = 0; i < image.values.size(); ++i)
      out[i] = stored_value<T>(image.values[i], image.dims, i, path);
  });
  write_file(path, *nim);
}

void write_nifti_displacement(const std::string& path, const ImageVolume& grid,
                              const std::vector<float>& displacement_lps_m) {
  const std::size_t n = grid.voxel_count();
  require(displacement_lps_m.size() == kVectorComponents * n,
          "displacement has " + std::to_string(displacement_lps_m.size()) + " floats for " +
              std::to_string(n) + " voxels (3 per voxel expected)",
          path);
  NiftiPtr nim = new_image(grid.dims, int(kVectorComponents), NIFTI_TYPE_FLOAT32, path);
  set_geometry(*nim, grid.affine_lps_m, path);
  nim->intent_code = NIFTI_INTENT_DISPVECT;
  set_text(nim->intent_name, sizeof nim->intent_name, "displacement");
  set_text(nim->descrip, sizeof nim->descrip, "VoxBreast displacement u: x -> x + u(x), RAS mm");
  // NIfTI stores the component axis slowest (dim[5]); components in the file's RAS frame, mm.
  auto* out = static_cast<float*>(nim->data);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t c = 0; c < kVectorComponents; ++c) {
      const float u = displacement_lps_m[kVectorComponents * i + c];
      require(std::isfinite(u), "displacement is not finite at " + voxel_name(grid.dims, i), path);
      out[c * n + i] = float(kLpsRasSign[c] * double(u) / kMetresPerMm);
    }
  }
  write_file(path, *nim);
}

ImageVolume read_nifti_displacement(const std::string& path,
                                    std::vector<float>& displacement_lps_m) {
  LoadedNifti file = load(path, int(kVectorComponents));
  const int intent = file.nim->intent_code;
  require(intent == NIFTI_INTENT_DISPVECT || intent == NIFTI_INTENT_VECTOR,
          "intent code " + std::to_string(intent) + " is not a displacement field", path,
          "expected 1006 (NIFTI_INTENT_DISPVECT) or 1007 (NIFTI_INTENT_VECTOR)");
  // DISPVECT components are RAS (ITK >= 5.4, Slicer); VECTOR ones are ITK's LPS, unconverted.
  const double unit = metres_per_unit(*file.nim, path);
  std::array<double, 3> factor{unit, unit, unit};
  if (intent == NIFTI_INTENT_DISPVECT)
    for (std::size_t c = 0; c < kVectorComponents; ++c) factor[c] *= kLpsRasSign[c];

  const std::vector<float> stored = scaled_values(*file.nim);
  const std::size_t n = file.grid.voxel_count();
  displacement_lps_m.resize(kVectorComponents * n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t c = 0; c < kVectorComponents; ++c)
      displacement_lps_m[kVectorComponents * i + c] = float(factor[c] * stored[c * n + i]);
  return std::move(file.grid);
}

}  // namespace vb
