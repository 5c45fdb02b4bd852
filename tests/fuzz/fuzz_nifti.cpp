/// libFuzzer target: vb::read_nifti (and vb::read_nifti_displacement) on arbitrary file contents.
/// Built and run by scripts/fuzz.sh; seeds in tests/fuzz/corpus/nifti/.
///
/// Input layout: byte 0 is a flag byte, the rest is the payload.
///   flag & 3 == 0 (or 3): the payload is written as `<tmp>/input.nii`
///   flag & 3 == 1:        the payload is gzip-compressed here and written as `input.nii.gz`
///                         (the fuzzer's mutations reach the NIfTI parser through znzlib's gzip path)
///   flag & 3 == 2:        the payload is written as-is as `input.nii.gz` (corrupt/raw gzip streams)
///   flag & 4:             also call read_nifti_displacement on the same file
/// vb::Error is the expected outcome for bad input; any other exception, a crash or a sanitizer
/// report is a finding. With VB_FUZZ_VERBOSE=1 in the environment each call's outcome is printed
/// (for replaying single inputs: VB_FUZZ_VERBOSE=1 build/fuzz/fuzz_nifti FILE).
#include <unistd.h>
#include <zlib.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

#include "engine/error.hpp"
#include "tests/fuzz/fuzz_support.hpp"
#include "io/nifti_io.hpp"

namespace fs = std::filesystem;

namespace {

void write_plain(const fs::path& path, const std::uint8_t* data, std::size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  if (!out) {
    std::fprintf(stderr, "fuzz_nifti: cannot write %s\n", path.c_str());
    std::abort();
  }
}

void write_gzip(const fs::path& path, const std::uint8_t* data, std::size_t size) {
  gzFile out = gzopen(path.c_str(), "wb1");
  const bool ok = out != nullptr && (size == 0 || gzwrite(out, data, unsigned(size)) == int(size));
  if (!ok || gzclose(out) != Z_OK) {
    std::fprintf(stderr, "fuzz_nifti: cannot write %s\n", path.c_str());
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t flag = data[0];
  const std::uint8_t* payload = data + 1;
  const std::size_t payload_size = size - 1;

  const fs::path plain = vb::fuzz::work_dir("nifti") / "input.nii";
  const fs::path gzip = vb::fuzz::work_dir("nifti") / "input.nii.gz";
  // Only the file of this input exists, so a run never depends on the previous input.
  std::error_code ignored;
  fs::remove(plain, ignored);
  fs::remove(gzip, ignored);

  fs::path path;
  switch (flag & 3) {
    case 1: path = gzip; write_gzip(path, payload, payload_size); break;
    case 2: path = gzip; write_plain(path, payload, payload_size); break;
    default: path = plain; write_plain(path, payload, payload_size); break;
  }

  try {
    const vb::ImageVolume image = vb::read_nifti(path.string());
    // What the reader promises: one value per voxel of a non-empty grid.
    if (image.values.size() != image.voxel_count() || image.voxel_count() == 0) {
      std::fprintf(stderr, "fuzz_nifti: read_nifti returned %zu values for %zu voxels\n",
                   image.values.size(), image.voxel_count());
      std::abort();
    }
    if (vb::fuzz::verbose())
      std::fprintf(stderr, "read_nifti %s: %dx%dx%d voxels, modality '%s'\n", path.c_str(),
                   image.dims[0], image.dims[1], image.dims[2], image.modality.c_str());
  } catch (const vb::Error& e) {
    if (vb::fuzz::verbose()) std::fprintf(stderr, "read_nifti: vb::Error: %s\n", e.what());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz_nifti: read_nifti threw a non-vb::Error exception: %s\n", e.what());
    std::abort();
  }

  if (flag & 4) {
    try {
      std::vector<float> displacement;
      const vb::ImageVolume grid = vb::read_nifti_displacement(path.string(), displacement);
      if (displacement.size() != 3 * grid.voxel_count()) {
        std::fprintf(stderr, "fuzz_nifti: read_nifti_displacement returned %zu floats for %zu "
                     "voxels\n", displacement.size(), grid.voxel_count());
        std::abort();
      }
      if (vb::fuzz::verbose())
        std::fprintf(stderr, "read_nifti_displacement: %dx%dx%d voxels\n", grid.dims[0],
                     grid.dims[1], grid.dims[2]);
    } catch (const vb::Error& e) {
      if (vb::fuzz::verbose()) std::fprintf(stderr, "read_nifti_displacement: vb::Error: %s\n", e.what());
    } catch (const std::exception& e) {
      std::fprintf(stderr,
                   "fuzz_nifti: read_nifti_displacement threw a non-vb::Error exception: %s\n",
                   e.what());
      std::abort();
    }
  }
  return 0;
}
