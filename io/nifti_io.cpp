#include "io/nifti_io.hpp"

#include <nifti/nifti2_io.h>
#include <zlib.h>

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <system_error>
#include <type_traits>
#include <vector>

#include "engine/error.hpp"
#include "io/atomic_file.hpp"
#include "io/gzip_blocks.hpp"
#include "io/system_reason.hpp"

namespace vb {
namespace {

// ---- nifti_clib plumbing ---------------------------------------------------------------------

struct NiftiFree {
  void operator()(nifti_image* nim) const { nifti_image_free(nim); }
};
using NiftiPtr = std::unique_ptr<nifti_image, NiftiFree>;

/// Debug level 0 silences nifti_clib's debug and warning output, but not all of its messages: some
/// error paths (header conversion, a seek past the end of the file) print "** ..." to stderr at
/// any level. read_raw_header and require_voxel_bytes refuse the inputs known to lead there before
/// nifti_clib sees them, so such lines should be rare (a fuzzing run printed none), not impossible.
/// The caller gets our vb::Error either way.
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

// ---- reading: our own header checks, before nifti_clib sees the file -------------------------
//
// nifti_clib 3.0.1 trusts the header: nifti_convert_n2hdr2nim copies dim[0] + 1 entries of a
// NIfTI-2 dim[] into its 8-entry array (stack corruption for dim[0] > 7), and nifti_image_load
// allocates nvox × nbyper bytes before it reads any of them (4 GB for a 360-byte file). So the
// raw header is read (through znzlib, as nifti_clib reads it) and checked here first, together
// with the file's size; nifti_image_read only ever sees headers that passed.

/// Largest image read: 2^31 stored values (8 GiB as float).
constexpr std::uint64_t kMaxVoxels = std::uint64_t(1) << 31;
/// Deflate never expands more than 1032:1 (a 258-byte match coded in 2 bits).
constexpr std::uint64_t kMaxDeflateRatio = 1032;
constexpr std::size_t kNifti1HeaderSize = sizeof(nifti_1_header);
constexpr std::size_t kNifti2HeaderSize = sizeof(nifti_2_header);
static_assert(kNifti1HeaderSize == 348 && kNifti2HeaderSize == 540);
constexpr const char* kNotNifti = "not a readable NIfTI file";
constexpr const char* kCompleteFileHint = "check that the file is a complete .nii or .nii.gz file";
constexpr const char* kCorruptFileHint =
    "the file is incomplete or corrupt; write or download it again";

/// The header fields we rely on, in host byte order, as stored in the file.
struct RawHeader {
  int version = 0;          ///< 1 or 2
  bool single_file = true;  ///< magic n+1 / n+2: the voxels are in the same file
  std::array<std::int64_t, 8> dim{};
  int datatype = 0;
  std::size_t bytes_per_voxel = 0;
  std::array<double, 8> pixdim{};  ///< as stored: nifti_image's copy has zeros replaced by 1
  std::int64_t vox_offset = 0;
  std::uint64_t voxels = 0;  ///< dim[1] × … × dim[dim[0]]
};

std::uint32_t byte_swapped(std::uint32_t v) {
  return (v >> 24) | ((v >> 8) & 0xff00u) | ((v << 8) & 0xff0000u) | (v << 24);
}

/// 1 or 2 for a sizeof_hdr of 348 or 540, else 0.
int version_of_size(std::uint32_t sizeof_hdr) {
  if (sizeof_hdr == kNifti1HeaderSize) return 1;
  return sizeof_hdr == kNifti2HeaderSize ? 2 : 0;
}

/// znzread of bytes: how many were read, nullopt on an error (a corrupt gzip stream; znzread
/// passes gzread's -1 on as a huge size_t).
std::optional<std::size_t> znz_read_bytes(void* buffer, std::size_t bytes, znzFile file) {
  const std::size_t got = znzread(buffer, 1, bytes, file);
  if (got > bytes) return std::nullopt;
  return got;
}

/// The gzip magic (1f 8b) at the start, and the ISIZE trailer: the uncompressed size modulo 2^32
/// of the last gzip member (RFC 1952), read from the last 4 bytes.
std::optional<std::uint32_t> gzip_isize(const std::string& file, std::uint64_t size) {
  std::ifstream in(file, std::ios::binary);
  unsigned char magic[2] = {0, 0}, trailer[4] = {0, 0, 0, 0};
  in.read(reinterpret_cast<char*>(magic), 2);
  if (!in || magic[0] != 0x1f || magic[1] != 0x8b || size < 18) return std::nullopt;
  in.seekg(std::streamoff(size - 4));
  in.read(reinterpret_cast<char*>(trailer), 4);
  if (!in) return std::nullopt;
  return std::uint32_t(trailer[0]) | std::uint32_t(trailer[1]) << 8 |
         std::uint32_t(trailer[2]) << 16 | std::uint32_t(trailer[3]) << 24;
}

/// Decompresses `file` through znzlib and counts its bytes, stopping at `needed`: no large buffer.
bool gzip_stream_has(const std::string& file, std::uint64_t needed) {
  znzFile in = znzopen(file.c_str(), "rb", 1);
  if (znz_isnull(in)) return false;
  std::vector<char> buffer(std::size_t(1) << 16);
  std::uint64_t count = 0;
  while (count < needed) {
    const std::optional<std::size_t> got = znz_read_bytes(buffer.data(), buffer.size(), in);
    if (!got || *got == 0) break;
    count += *got;
  }
  znzclose(in);
  return count >= needed;
}

/// Whether `file`, read through znzlib as nifti_clib reads it (gzip for a .gz name), holds at
/// least `needed` bytes. Plain: its size. Gzip: deflate expands at most 1032:1, which bounds what
/// a small file can claim; then the ISIZE trailer settles it cheaply when it is large enough.
/// ISIZE can say too little for a valid file (one over 4 GiB, where it wraps around, or one made
/// of several gzip members, where it counts only the last): then the stream is decompressed and
/// counted up to `needed`, once more than reading it costs, in such files only.
bool file_holds(const std::string& file, std::int64_t offset, std::uint64_t data_bytes) {
  std::error_code ec;
  const std::uint64_t size = std::filesystem::file_size(file, ec);
  if (ec || offset < 0) return false;
  const std::uint64_t needed = std::uint64_t(offset) + data_bytes;  // < 2^63 + 2^34: no overflow
  const std::optional<std::uint32_t> isize =
      nifti_is_gzfile(file.c_str()) ? gzip_isize(file, size) : std::nullopt;
  if (!isize) return needed <= size;  // znzlib reads a .gz name without gzip magic as it is
  if (needed / kMaxDeflateRatio > size) return false;
  return *isize >= needed || gzip_stream_has(file, needed);
}

/// A gzip file is decompressed to its end once before it is used: nifti_clib reads only the bytes
/// the header asks for and never reaches a member's trailer, where zlib checks the CRC-32 and the
/// length (ISIZE). Corrupt data inside a stream would otherwise be read as voxels. Several
/// members are checked one after the other; bytes after the last member are refused too.
void require_intact_gzip(const std::string& file, const std::string& path) {
  if (!nifti_is_gzfile(file.c_str())) return;
  std::ifstream in(file, std::ios::binary);
  require(bool(in), "cannot open file", path, "check its permissions");
  char magic[2] = {0, 0};
  in.read(magic, 2);
  if (!in || magic[0] != '\x1f' || magic[1] != '\x8b') return;  // znzlib reads it as it is
  in.seekg(0);
  z_stream z{};
  require(inflateInit2(&z, 16 + MAX_WBITS) == Z_OK, "zlib cannot start inflating", path);
  std::vector<unsigned char> input(std::size_t(1) << 16), output(std::size_t(1) << 18);
  int status = Z_OK;
  bool member_ended = false;  // the stream ends cleanly only right after a member's trailer
  while (true) {
    if (z.avail_in == 0) {
      in.read(reinterpret_cast<char*>(input.data()), std::streamsize(input.size()));
      z.next_in = input.data();
      z.avail_in = uInt(in.gcount());
      if (z.avail_in == 0) break;
    }
    if (member_ended) {  // another member follows (RFC 1952 allows several)
      inflateReset(&z);
      member_ended = false;
    }
    z.next_out = output.data();
    z.avail_out = uInt(output.size());
    status = inflate(&z, Z_NO_FLUSH);
    if (status == Z_STREAM_END) member_ended = true;
    else if (status != Z_OK && status != Z_BUF_ERROR) break;
  }
  const std::string reason = z.msg ? z.msg : "";
  inflateEnd(&z);
  require(member_ended,
          status == Z_DATA_ERROR ? "corrupt gzip stream (" + reason + ")"
                                 : std::string("corrupt gzip stream: it is truncated, ending before its trailer"),
          path, kCorruptFileHint);
}

/// The voxels (`data_bytes` from byte `offset` of `file`) must be there before nifti_image_load
/// allocates room for them.
void require_voxel_bytes(const std::string& file, std::int64_t offset, std::uint64_t data_bytes,
                         const std::string& path) {
  require(file_holds(file, offset, data_bytes),
          "voxel data missing or truncated: the header describes " + std::to_string(data_bytes) +
              " bytes of voxels from byte " + std::to_string(offset) + " of " +
              (file == path ? std::string("the file") : "'" + file + "'") +
              ", which does not hold that many",
          path, kCorruptFileHint);
}

/// Checks of the fields both versions share, after they were copied into `raw`.
void check_raw_header(RawHeader& raw, int bitpix, std::size_t header_size,
                      const std::string& path) {
  const std::int64_t ndim = raw.dim[0];
  require(ndim >= 1 && ndim <= 7,
          "dim[0] = " + std::to_string(ndim) + ": the number of dimensions must be 1 to 7", path,
          kCompleteFileHint);
  raw.voxels = 1;
  std::string shape;
  for (int d = 1; d <= ndim; ++d) {
    const std::int64_t n = raw.dim[std::size_t(d)];
    require(n >= 1, "dim[" + std::to_string(d) + "] = " + std::to_string(n) + " is not a size",
            path, kCompleteFileHint);
    shape += (d > 1 ? " x " : "") + std::to_string(n);
    require(std::uint64_t(n) <= kMaxVoxels / raw.voxels,
            "the image is larger than " + std::to_string(kMaxVoxels) + " voxels (dim " + shape +
                (d < ndim ? " x ..." : "") + "): not read",
            path, "crop or downsample it first");
    raw.voxels *= std::uint64_t(n);
  }
  require(with_voxel_type(raw.datatype, [&](auto tag) { raw.bytes_per_voxel = sizeof tag; }),
          std::string("unsupported voxel type ") + nifti_datatype_string(raw.datatype), path,
          "use int8/16/32, uint8/16/32, float32 or float64");
  require(std::size_t(bitpix) == 8 * raw.bytes_per_voxel,
          "bitpix = " + std::to_string(bitpix) + " does not match the voxel type " +
              nifti_datatype_string(raw.datatype) + " (" +
              std::to_string(8 * raw.bytes_per_voxel) + " bits)",
          path, kCompleteFileHint);
  require(raw.vox_offset >= 0, "vox_offset = " + std::to_string(raw.vox_offset) + " is negative",
          path, kCompleteFileHint);
  require(!raw.single_file || std::uint64_t(raw.vox_offset) >= header_size,
          "vox_offset = " + std::to_string(raw.vox_offset) + " lies inside the " +
              std::to_string(header_size) + "-byte header",
          path, kCompleteFileHint);
}

template <class Header>
void copy_fields(const Header& h, RawHeader& raw) {
  raw.single_file = NIFTI_ONEFILE(h);
  for (std::size_t d = 0; d < 8; ++d) {
    raw.dim[d] = h.dim[d];
    raw.pixdim[d] = h.pixdim[d];
  }
  raw.datatype = h.datatype;
}

/// Reads and checks the header of `file` (the header nifti_clib will read for `path`, named in
/// the errors): NIfTI-1 (sizeof_hdr 348) or NIfTI-2 (540), either byte order, gzip or not.
RawHeader read_raw_header(const std::string& file, const std::string& path) {
  std::array<char, kNifti2HeaderSize> bytes{};
  znzFile in = znzopen(file.c_str(), "rb", nifti_is_gzfile(file.c_str()));
  require(!znz_isnull(in), "cannot open file", path, "check its permissions");
  const std::optional<std::size_t> read = znz_read_bytes(bytes.data(), bytes.size(), in);
  znzclose(in);
  require(read.has_value(), std::string(kNotNifti) + ": its gzip stream is corrupt", path,
          kCompleteFileHint);
  const std::size_t got = *read;
  const auto cut_short = [&](std::size_t size) {
    return std::string(kNotNifti) + ": the header is cut short (" + std::to_string(got) + " of " +
           std::to_string(size) + " bytes)";
  };
  require(got >= kNifti1HeaderSize, cut_short(kNifti1HeaderSize), path, kCompleteFileHint);

  std::uint32_t sizeof_hdr = 0;
  std::memcpy(&sizeof_hdr, bytes.data(), sizeof sizeof_hdr);
  RawHeader raw;
  raw.version = version_of_size(sizeof_hdr);
  const bool swapped = raw.version == 0;  // other byte order, if it is NIfTI at all
  if (swapped) raw.version = version_of_size(byte_swapped(sizeof_hdr));
  require(raw.version != 0,
          std::string(kNotNifti) + ": sizeof_hdr is " + std::to_string(sizeof_hdr) +
              ", neither 348 (NIfTI-1) nor 540 (NIfTI-2) in either byte order",
          path, kCompleteFileHint);

  if (raw.version == 1) {
    nifti_1_header h;
    std::memcpy(&h, bytes.data(), sizeof h);
    require(NIFTI_VERSION(h) != 0, "ANALYZE 7.5 file: it has no defined orientation", path,
            "convert it to NIfTI");
    require(NIFTI_VERSION(h) == 1,
            std::string(kNotNifti) + ": NIfTI-1 header size with the magic of another version",
            path, kCompleteFileHint);
    if (swapped) swap_nifti_header(&h, 1);
    copy_fields(h, raw);
    // nifti_clib converts the float to int: only whole numbers in int range are offsets.
    const float offset = h.vox_offset;
    require(std::isfinite(offset) && offset >= 0.0f && offset < 2147483648.0f &&
                offset == std::floor(offset),
            "vox_offset = " + std::to_string(offset) + " is not a byte offset", path,
            kCompleteFileHint);
    raw.vox_offset = std::int64_t(offset);
    check_raw_header(raw, h.bitpix, kNifti1HeaderSize, path);
  } else {
    require(got >= kNifti2HeaderSize, cut_short(kNifti2HeaderSize), path, kCompleteFileHint);
    nifti_2_header h;
    std::memcpy(&h, bytes.data(), sizeof h);
    require(NIFTI_VERSION(h) == 2,
            std::string(kNotNifti) + ": NIfTI-2 header size without the NIfTI-2 magic", path,
            kCompleteFileHint);
    if (swapped) swap_nifti_header(&h, 2);
    copy_fields(h, raw);
    raw.vox_offset = h.vox_offset;
    check_raw_header(raw, h.bitpix, kNifti2HeaderSize, path);
  }
  return raw;
}

// ---- reading ---------------------------------------------------------------------------------

/// A header that passed read_raw_header, and nifti_clib's image of it (voxels not loaded).
struct OpenedNifti {
  RawHeader raw;
  NiftiPtr nim;
};

OpenedNifti open_header(const std::string& path) {
  quiet_nifti_clib();
  std::error_code ec;
  require(std::filesystem::exists(path, ec), "file not found", path);
  require(std::filesystem::is_regular_file(path, ec), "not a regular file", path);
  // The file nifti_image_read will take the header from: `path` itself for a .nii or .nii.gz.
  const std::unique_ptr<char, void (*)(void*)> header_file(nifti_findhdrname(path.c_str()),
                                                           std::free);
  require(header_file != nullptr, std::string(kNotNifti) + ": no NIfTI file name", path,
          "NIfTI files are named .nii or .nii.gz");
  const std::string header_path = header_file.get();
  OpenedNifti file{read_raw_header(header_path, path), nullptr};
  const RawHeader& raw = file.raw;
  const std::uint64_t data_bytes = raw.voxels * raw.bytes_per_voxel;
  // Before nifti_image_read: it reads header extensions up to vox_offset.
  if (raw.single_file) require_voxel_bytes(header_path, raw.vox_offset, data_bytes, path);
  require_intact_gzip(header_path, path);

  file.nim.reset(nifti_image_read(path.c_str(), /*read_data=*/0));
  require(file.nim != nullptr, std::string(kNotNifti) + " (bad or truncated header)", path,
          kCompleteFileHint);
  const nifti_image& nim = *file.nim;
  require(nim.ndim == raw.dim[0] && std::uint64_t(nim.nvox) == raw.voxels &&
              nim.datatype == raw.datatype && std::size_t(nim.nbyper) == raw.bytes_per_voxel &&
              nim.iname != nullptr,
          "nifti_clib read the header differently from our checks", path);
  // Where nifti_image_load will read the voxels; checked above for a one-file header.
  const bool checked = raw.single_file && header_path == nim.iname &&
                       nim.iname_offset == raw.vox_offset;
  if (!checked) require_voxel_bytes(nim.iname, nim.iname_offset, data_bytes, path);
  if (nim.iname != header_path) require_intact_gzip(nim.iname, path);
  return file;
}

/// Loads the voxels after the header has been accepted; a short read is a truncated file.
void load_voxels(nifti_image& nim, const std::string& path) {
  require(nifti_image_load(&nim) >= 0 && nim.data != nullptr, "voxel data missing or truncated",
          path, kCorruptFileHint);
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

/// The qform and the bare-pixdim fallback take the spacing from pixdim, as stored in the file.
void check_pixdim(const RawHeader& raw, const std::string& path) {
  for (std::size_t d = 1; d <= 3; ++d)
    require(std::isfinite(raw.pixdim[d]) && raw.pixdim[d] > 0.0,
            "voxel spacing pixdim[" + std::to_string(d) + "] = " + std::to_string(raw.pixdim[d]) +
                " is not positive",
            path);
}

/// Voxel index -> file world (RAS, file unit): sform, else qform, else diag(pixdim).
Eigen::Matrix4d file_affine(const nifti_image& nim, const RawHeader& raw,
                            const std::string& path) {
  if (nim.sform_code > 0) return to_eigen(nim.sto_xyz);
  check_pixdim(raw, path);
  if (nim.qform_code > 0) return to_eigen(nim.qto_xyz);
  return Eigen::Vector4d(nim.pixdim[1], nim.pixdim[2], nim.pixdim[3], 1.0).asDiagonal();
}

/// Dims and the LPS-metre affine; values left empty.
ImageVolume read_grid(const nifti_image& nim, const RawHeader& raw, const std::string& path) {
  ImageVolume grid;
  for (int d = 0; d < 3; ++d) {
    const std::int64_t n = d < nim.dim[0] ? nim.dim[d + 1] : 1;
    require(
        n >= 1 && n <= std::numeric_limits<int>::max(),
        "grid size dim[" + std::to_string(d + 1) + "] = " + std::to_string(n) + " not supported",
        path);
    grid.dims[std::size_t(d)] = int(n);
  }
  grid.affine_lps_m = ras_lps_flip() * file_affine(nim, raw, path);
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
  OpenedNifti opened = open_header(path);
  LoadedNifti file{std::move(opened.nim), {}};
  check_extra_dims(*file.nim, components, path);
  file.grid = read_grid(*file.nim, opened.raw, path);
  load_voxels(*file.nim, path);
  return file;
}

/// Runs a reader; running out of memory (an image within the limits, on a small machine) is a
/// vb::Error naming the file like any other failure.
template <class Read>
auto guard_memory(const std::string& path, Read&& read) {
  try {
    return read();
  } catch (const std::bad_alloc&) {
    throw Error("not enough memory to read the image", path, "free memory or use a smaller image");
  }
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

/// A NIfTI-1 header (no voxel buffer: write_file produces the voxels block by block):
/// (nx, ny, nz) or, with 3 components, (nx, ny, nz, 1, 3).
NiftiPtr new_image(const std::array<int, 3>& dims, int components, int datatype,
                   const std::string& path) {
  quiet_nifti_clib();
  check_dims(dims, path);
  const std::int64_t dim[8] = {
      components == 1 ? 3 : 5, dims[0], dims[1], dims[2], 1, components, 1, 1};
  NiftiPtr nim(nifti_make_new_nim(dim, datatype, /*data_fill=*/0));
  require(nim != nullptr, "cannot allocate the NIfTI image", path);
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

/// Header, extension flag, then the voxels, produced by fill(first voxel, count, out) in blocks
/// on all cores and gzip-compressed for .nii.gz (write_blocks), into an atomic temporary file.
template <class T, class Fill>
void write_file(const std::string& path, nifti_image& nim, Fill fill, const BlocksWritten& progress) {
  const bool gzip = gzip_for(path);
  nim.iname_offset = kNifti1DataOffset;
  nifti_1_header header{};
  require(nifti_convert_nim2n1hdr(&nim, &header) == 0, "cannot build the NIfTI-1 header", path);
  require(std::size_t(nim.nbyper) == sizeof(T), "the NIfTI voxel type does not match its writer", path);
  std::string prefix(reinterpret_cast<const char*>(&header), sizeof header);
  prefix.append(4, '\0');  // no extension
  static_assert(kNifti1DataOffset % 4 == 0, "blocks must split between voxels");

  AtomicOutput out(path);
  std::FILE* file = std::fopen(out.temp_path().c_str(), "wb");
  require(file != nullptr, "cannot create file", path, "check the folder and its permissions");
  bool ok = false;
  errno = 0;
  try {
    ok = write_blocks(file, prefix, std::size_t(nim.nvox) * sizeof(T), [&](std::size_t offset, unsigned char* bytes,
                                                                           std::size_t size) {
      T* voxels = reinterpret_cast<T*>(bytes);  // offset and size are whole voxels (4-byte aligned blocks)
      fill(offset / sizeof(T), size / sizeof(T), voxels);
    }, gzip, 6, progress);
  } catch (...) {
    std::fclose(file);
    throw;
  }
  const int write_errno = ok ? 0 : errno;
  ok = std::fclose(file) == 0 && ok;  // closing flushes
  const int error = write_errno ? write_errno : errno;
  require(ok, error ? "cannot write file: " + system_reason(error) : std::string("cannot write file"), path,
          "check free disk space");
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
    // Per voxel: the message is built only on failure (building it each time cost ~1 µs a voxel).
    if (!(std::isfinite(rounded) && rounded >= double(std::numeric_limits<T>::lowest()) &&
          rounded <= double(std::numeric_limits<T>::max())))
      throw Error("value " + std::to_string(value) + " at " + voxel_name(dims, index) +
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
  return guard_memory(path, [&] {
    LoadedNifti file = load(path, 1);
    file.grid.values = scaled_values(*file.nim);
    file.grid.modality = file.nim->intent_code == NIFTI_INTENT_LABEL ? "LABEL" : "";
    return std::move(file.grid);
  });
}

void write_nifti(const std::string& path, const ImageVolume& image, NiftiType type,
                 const std::function<void(double)>& progress) {
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
    write_file<T>(path, *nim, [&](std::size_t first, std::size_t count, T* out) {
      for (std::size_t i = 0; i < count; ++i)
        out[i] = stored_value<T>(image.values[first + i], image.dims, first + i, path);
    }, progress);
  });
}

void write_nifti_displacement(const std::string& path, const ImageVolume& grid,
                              const std::vector<float>& displacement_lps_m, NiftiDisplacementLayout layout,
                              const std::function<void(double)>& progress) {
  const std::size_t n = grid.voxel_count();
  require(displacement_lps_m.size() == kVectorComponents * n,
          "displacement has " + std::to_string(displacement_lps_m.size()) + " floats for " +
              std::to_string(n) + " voxels (3 per voxel expected)",
          path);
  NiftiPtr nim = new_image(grid.dims, int(kVectorComponents), NIFTI_TYPE_FLOAT32, path);
  set_geometry(*nim, grid.affine_lps_m, path);
  const bool ras = layout == NiftiDisplacementLayout::DispVectRas;
  nim->intent_code = ras ? NIFTI_INTENT_DISPVECT : NIFTI_INTENT_VECTOR;
  set_text(nim->intent_name, sizeof nim->intent_name, "displacement");
  set_text(nim->descrip, sizeof nim->descrip,
           ras ? "VoxBreast displacement u: x -> x + u(x), RAS mm" : "VoxBreast displacement u: x -> x + u(x), LPS mm");
  // NIfTI stores the component axis slowest (dim[5]); components in mm, RAS or LPS by layout.
  write_file<float>(path, *nim, [&](std::size_t first, std::size_t count, float* out) {
    for (std::size_t f = first; f < first + count; ++f) {
      const std::size_t c = f / n, i = f % n;
      const float u = displacement_lps_m[kVectorComponents * i + c];
      if (!std::isfinite(u)) throw Error("displacement is not finite at " + voxel_name(grid.dims, i), path);
      out[f - first] = float((ras ? kLpsRasSign[c] : 1.0) * double(u) / kMetresPerMm);
    }
  }, progress);
}

ImageVolume read_nifti_displacement(const std::string& path,
                                    std::vector<float>& displacement_lps_m) {
  return guard_memory(path, [&] {
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
  });
}

}  // namespace vb
