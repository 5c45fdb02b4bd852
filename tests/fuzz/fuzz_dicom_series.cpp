/// libFuzzer target: DICOM series assembly (vb::list_dicom_series, vb::read_dicom_series) on a
/// folder of up to 4 files cut from the input. Built and run by scripts/fuzz.sh; seeds in
/// tests/fuzz/corpus/dicom/.
///
/// Input layout: byte 0 is a flag byte, then the files' contents.
///   flag & 3:   number of files - 1 (1..4). Every file but the last is a 2-byte little-endian
///               length followed by that many bytes (fewer at the end of the input); the last
///               file takes the rest. Files are named f0.dcm .. f3.dcm in one folder.
///   flag & 4:   each file is prefixed with a valid Part 10 preamble and File Meta Information
///               (Explicit VR Little Endian, CT Image Storage), so its bytes are the dataset: the
///               fuzzer reaches the series logic without having to find "DICM" first
///   flag & 8:   DicomReadOptions::allow_gaps
///   flag & 16:  DicomReadOptions::accept_any_modality
///   flag & 32:  read the first series that list_dicom_series found, by UID (else UID "")
/// vb::Error is the expected outcome for bad input; any other exception, a crash or a sanitizer
/// report is a finding. With VB_FUZZ_VERBOSE=1 in the environment each call's outcome is printed
/// (for replaying single inputs: VB_FUZZ_VERBOSE=1 build/fuzz/fuzz_dicom_series FILE).
#include <unistd.h>

#include <algorithm>
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
#include "io/dicom_io.hpp"

namespace fs = std::filesystem;

namespace {

constexpr int kMaxFiles = 4;

// ---- a minimal Part 10 header (preamble, "DICM", group 0002) ---------------------------------

void put16(std::string& out, unsigned v) {
  out += char(v & 0xff);
  out += char((v >> 8) & 0xff);
}

void put32(std::string& out, unsigned long v) {
  put16(out, unsigned(v & 0xffff));
  put16(out, unsigned((v >> 16) & 0xffff));
}

/// Explicit VR element of group 0002 with a short (16-bit length) VR.
void put_short(std::string& out, unsigned element, const char* vr, std::string value) {
  if (value.size() % 2) value += '\0';  // UI values are padded with NUL to even length
  put16(out, 0x0002);
  put16(out, element);
  out += vr;
  put16(out, unsigned(value.size()));
  out += value;
}

std::string part10_header() {
  std::string group;
  // (0002,0001) OB FileMetaInformationVersion 00\01: a long VR (reserved 2 bytes, 32-bit length)
  put16(group, 0x0002);
  put16(group, 0x0001);
  group += "OB";
  put16(group, 0);
  put32(group, 2);
  group += std::string("\x00\x01", 2);
  put_short(group, 0x0002, "UI", "1.2.840.10008.5.1.4.1.1.2");  // CT Image Storage
  put_short(group, 0x0003, "UI", "1.2.826.0.1.3680043.2.1125.1.1");
  put_short(group, 0x0010, "UI", "1.2.840.10008.1.2.1");  // Explicit VR Little Endian

  std::string out(128, '\0');
  out += "DICM";
  put16(out, 0x0002);  // (0002,0000) UL FileMetaInformationGroupLength
  put16(out, 0x0000);
  out += "UL";
  put16(out, 4);
  put32(out, group.size());
  return out + group;
}

void write_file(const fs::path& path, const std::string& prefix, const std::uint8_t* data,
                std::size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(prefix.data(), std::streamsize(prefix.size()));
  out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  if (!out) {
    std::fprintf(stderr, "fuzz_dicom_series: cannot write %s\n", path.c_str());
    std::abort();
  }
}

[[noreturn]] void finding(const char* call, const char* what) {
  std::fprintf(stderr, "fuzz_dicom_series: %s threw a non-vb::Error exception: %s\n", call, what);
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // A missing data dictionary would turn every input into the same vb::Error: say so at once.
  try {
    vb::list_dicom_series(vb::fuzz::work_dir("dicom").string());
  } catch (const vb::Error& e) {
    std::fprintf(stderr, "fuzz_dicom_series: DICOM reading is not usable here: %s\n", e.what());
    std::exit(1);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const std::string header = part10_header(), no_header;
  const std::uint8_t flag = data[0];
  const int files = (flag & 3) + 1;
  const std::string& prefix = (flag & 4) ? header : no_header;
  std::size_t at = 1;

  // Only this input's files are in the folder, so a run never depends on the previous input.
  std::error_code ignored;
  for (int n = 0; n < kMaxFiles; ++n)
    fs::remove(vb::fuzz::work_dir("dicom") / ("f" + std::to_string(n) + ".dcm"), ignored);
  for (int n = 0; n < files; ++n) {
    std::size_t length = size - at;
    if (n + 1 < files) {
      std::size_t declared = 0;
      if (at < size) declared = data[at++];
      if (at < size) declared |= std::size_t(data[at++]) << 8;
      length = std::min(declared, size - at);
    }
    write_file(vb::fuzz::work_dir("dicom") / ("f" + std::to_string(n) + ".dcm"), prefix, data + at, length);
    at += length;
  }

  const std::string dir = vb::fuzz::work_dir("dicom").string();
  std::string first_uid;
  try {
    const std::vector<vb::DicomSeriesInfo> series = vb::list_dicom_series(dir);
    for (const auto& info : series)
      if (info.files < 1 || info.files > files) {
        std::fprintf(stderr, "fuzz_dicom_series: a series of %d files from %d files\n",
                     info.files, files);
        std::abort();
      }
    if (!series.empty()) first_uid = series.front().series_uid;
    if (vb::fuzz::verbose())
      for (const auto& info : series)
        std::fprintf(stderr, "list_dicom_series: %s '%s' %d files\n", info.series_uid.c_str(),
                     info.modality.c_str(), info.files);
  } catch (const vb::Error& e) {
    if (vb::fuzz::verbose()) std::fprintf(stderr, "list_dicom_series: vb::Error: %s\n", e.what());
  } catch (const std::exception& e) {
    finding("list_dicom_series", e.what());
  }

  vb::DicomReadOptions options;
  options.allow_gaps = (flag & 8) != 0;
  options.accept_any_modality = (flag & 16) != 0;
  if (flag & 32) options.series_uid = first_uid;
  try {
    std::vector<std::string> warnings;
    const vb::ImageVolume volume = vb::read_dicom_series(dir, options, &warnings);
    if (volume.values.size() != volume.voxel_count() || volume.voxel_count() == 0 ||
        volume.dims[2] > files) {
      std::fprintf(stderr, "fuzz_dicom_series: read_dicom_series returned %zu values for "
                   "%dx%dx%d voxels\n", volume.values.size(), volume.dims[0], volume.dims[1],
                   volume.dims[2]);
      std::abort();
    }
    if (vb::fuzz::verbose())
      std::fprintf(stderr, "read_dicom_series: %dx%dx%d voxels, %zu warnings\n", volume.dims[0],
                   volume.dims[1], volume.dims[2], warnings.size());
  } catch (const vb::Error& e) {
    if (vb::fuzz::verbose()) std::fprintf(stderr, "read_dicom_series: vb::Error: %s\n", e.what());
  } catch (const std::exception& e) {
    finding("read_dicom_series", e.what());
  }
  return 0;
}
