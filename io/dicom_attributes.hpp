#pragma once
/// What every part of the DICOM reader and writer shares (internal to io/): DCMTK's one-time
/// set-up, the patient and study attributes carried into derived series, and typed access to a
/// dataset's attributes that reports the file on failure.
#include <dcmtk/config/osconfig.h>  // DCMTK: must come before its other headers
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcitem.h>

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>

#include "engine/error.hpp"

namespace vb::dicom {

/// Once per process: silence DCMTK's logger (library code must not write to stderr; errors reach
/// the caller as vb::Error) and register the JPEG, JPEG-LS and RLE decoders.
void init_dcmtk();

/// Patient and study attributes (plus the character set they are encoded in).
extern const std::array<DcmTagKey, 13> kCarriedTags;

/// ImageVolume::dicom_tags key of the source series' UID
constexpr const char* kSourceSeriesKey = "source_series_uid";
/// ImageVolume::dicom_tags keys of the source's SOPClassUID and of its slices' SOPInstanceUIDs in
/// k order, joined by '\\' as a multi-valued attribute is
constexpr const char* kSourceSopClassKey = "source_sop_class_uid";
constexpr const char* kSourceInstancesKey = "source_instance_uids";
constexpr const char* kCorruptFileHint = "the file may be truncated or corrupt; remove or replace it";

/// A DICOM UID under the 2.25 root made from `name` (a name-based, SHA-1, version 5 UUID in
/// VoxBreast's own namespace, PS3.5 B.2): the same name always gives the same UID, so files
/// written from the same content are byte-identical.
std::string name_based_uid(const std::string& name);

/// "gggg,eeee" in upper-case hex, as the standard prints tags.
std::string tag_key_text(const DcmTagKey& key);
std::optional<DcmTagKey> parse_tag_key(const std::string& text);

/// All values joined by '\', "" when absent.
std::string get_text(DcmItem& item, const DcmTagKey& key);
std::optional<double> get_number(DcmItem& item, const DcmTagKey& key, unsigned long pos = 0);
/// "Name (gggg,eeee)"
std::string tag_name(const DcmTagKey& key);
Uint16 get_uint16(DcmItem& item, const DcmTagKey& key, Uint16 fallback);

/// `count` numbers of a required attribute; throws naming the file when missing or malformed.
template <int count>
Eigen::Matrix<double, count, 1> require_numbers(DcmItem& item, const DcmTagKey& key, const std::string& path) {
  Eigen::Matrix<double, count, 1> values;
  for (int n = 0; n < count; ++n) {
    const auto value = get_number(item, key, unsigned(n));
    require(value.has_value(),
            "missing or malformed " + tag_name(key) + " (needs " + std::to_string(count) + " numbers)", path);
    values[n] = *value;
  }
  return values;
}

}  // namespace vb::dicom
