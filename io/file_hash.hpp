#pragma once
/// Content hashes of input files, so that a resumed study can tell that its data changed.
#include <string>

namespace vb {

/// SHA-256 (hex) of a file's bytes; of a folder (a DICOM series): of each regular file below it,
/// in name order, its path relative to the folder and its bytes. Throws vb::Error when a file
/// cannot be read.
std::string content_sha256(const std::string& path);

}  // namespace vb
