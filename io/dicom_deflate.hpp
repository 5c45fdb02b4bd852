#pragma once
/// Guarding DCMTK against a deflated dataset whose lengths lie (internal to io/).
#include <string>

namespace vb::dicom {

// DCMTK reads a deflated dataset (Deflated Explicit VR Little Endian) through zlib, where it
// cannot skip over a value to find the stream too short: it allocates each value as long as its
// length field says before reading it (a 1 kB file can ask for 4 GiB). In a plain file it skips
// large values and reads them on first access, so a false length only ends the parse. Hence a
// deflated dataset is walked here first, inflated in a fixed buffer as DCMTK will inflate it:
// every length it holds must be backed by inflated bytes before DCMTK reads it.

/// For a file DCMTK would read as a deflated dataset: the walk above, before DCMTK reads it;
/// throws vb::Error naming the file when a length is not backed. Other files pass untouched.
void check_deflated_dataset(const std::string& path);

}  // namespace vb::dicom
