#include "io/dicom_attributes.hpp"

#include <dcmtk/dcmdata/dcdict.h>
#include <dcmtk/dcmdata/dcrledrg.h>
#include <dcmtk/dcmjpeg/djdecode.h>
#include <dcmtk/dcmjpls/djdecode.h>
#include <dcmtk/oflog/oflog.h>

#include <cmath>
#include <cstdio>
#include <mutex>

namespace vb::dicom {

void init_dcmtk() {
  static std::once_flag once;
  std::call_once(once, [] {
    OFLog::getLogger("dcmtk").setLogLevel(OFLogger::OFF_LOG_LEVEL);
    DJDecoderRegistration::registerCodecs();
    DJLSDecoderRegistration::registerCodecs();
    DcmRLEDecoderRegistration::registerCodecs();
  });
  require(dcmDataDict.isDictionaryLoaded(), "the DICOM data dictionary is not loaded", {},
          "install DCMTK's dictionary (dicom.dic) or point DCMDICTPATH at it");
}

const std::array<DcmTagKey, 13> kCarriedTags = {DCM_SpecificCharacterSet,
                                                DCM_PatientName,
                                                DCM_PatientID,
                                                DCM_PatientBirthDate,
                                                DCM_PatientSex,
                                                DCM_StudyInstanceUID,
                                                DCM_StudyID,
                                                DCM_StudyDate,
                                                DCM_StudyTime,
                                                DCM_AccessionNumber,
                                                DCM_ReferringPhysicianName,
                                                DCM_StudyDescription,
                                                DCM_FrameOfReferenceUID};

std::string tag_key_text(const DcmTagKey& key) {
  char text[10];
  std::snprintf(text, sizeof text, "%04X,%04X", unsigned(key.getGroup()),
                unsigned(key.getElement()));
  return text;
}

std::optional<DcmTagKey> parse_tag_key(const std::string& text) {
  unsigned group = 0, element = 0;
  char tail = 0;
  if (text.size() != 9 || std::sscanf(text.c_str(), "%4x,%4x%c", &group, &element, &tail) != 2)
    return std::nullopt;
  return DcmTagKey(Uint16(group), Uint16(element));
}

std::string get_text(DcmItem& item, const DcmTagKey& key) {
  OFString value;
  return item.findAndGetOFStringArray(key, value).good() ? std::string(value.c_str()) : "";
}

std::optional<double> get_number(DcmItem& item, const DcmTagKey& key, unsigned long pos) {
  Float64 value = 0;
  if (item.findAndGetFloat64(key, value, pos).bad() || !std::isfinite(value)) return std::nullopt;
  return value;
}

std::string tag_name(const DcmTagKey& key) {
  return DcmTag(key).getTagName() + std::string(" (") + tag_key_text(key) + ")";
}

Uint16 get_uint16(DcmItem& item, const DcmTagKey& key, Uint16 fallback) {
  Uint16 value = fallback;
  return item.findAndGetUint16(key, value).good() ? value : fallback;
}

}  // namespace vb::dicom
