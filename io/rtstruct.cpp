#include "io/rtstruct.hpp"

#include <dcmtk/config/osconfig.h>  // DCMTK: must come before its other headers
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcuid.h>
#include <dcmtk/dcmrt/drtstrct.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <map>

#include "engine/error.hpp"
#include "io/atomic_file.hpp"
#include "io/dicom_attributes.hpp"
#include "voxbreast/config.hpp"

namespace vb {
namespace {

constexpr double kMmPerM = 1e3;

void check(const OFCondition& status, const std::string& what, const std::string& where) {
  require(status.good(), what + ": " + status.text(), where);
}

std::string text_of(const OFCondition& status, const OFString& value) { return status.good() ? value.c_str() : ""; }

/// One image of the referenced CT series.
struct ReferencedImage {
  std::string sop_class_uid, sop_instance_uid;
};

/// What an RTSTRUCT takes from the CT series it references.
struct ReferencedSeries {
  std::map<DcmTagKey, std::string> patient_study;  ///< patient and study attributes, as text
  std::string study_uid, series_uid, frame_uid;
  std::vector<ReferencedImage> images;
};

ReferencedSeries read_referenced_series(const std::string& dir) {
  ReferencedSeries s;
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (entry.is_regular_file()) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  require(!files.empty(), "the CT series folder holds no files", dir);
  static const DcmTagKey kCopied[] = {DCM_PatientName, DCM_PatientID, DCM_PatientBirthDate, DCM_PatientSex,
                                      DCM_StudyDate, DCM_StudyTime, DCM_ReferringPhysicianName, DCM_StudyID,
                                      DCM_AccessionNumber, DCM_StudyDescription};
  for (const auto& file : files) {
    DcmFileFormat ff;
    check(ff.loadFile(file.c_str()), "cannot read the CT slice", file.string());
    DcmDataset& d = *ff.getDataset();
    OFString value;
    const auto get = [&](const DcmTagKey& key) { return text_of(d.findAndGetOFStringArray(key, value), value); };
    if (s.images.empty()) {
      for (const DcmTagKey& key : kCopied) s.patient_study[key] = get(key);
      s.study_uid = get(DCM_StudyInstanceUID);
      s.series_uid = get(DCM_SeriesInstanceUID);
      s.frame_uid = get(DCM_FrameOfReferenceUID);
    }
    require(get(DCM_SeriesInstanceUID) == s.series_uid, "the folder holds more than one series", dir);
    s.images.push_back({get(DCM_SOPClassUID), get(DCM_SOPInstanceUID)});
  }
  require(!s.study_uid.empty() && !s.series_uid.empty() && !s.frame_uid.empty(),
          "the CT series lacks a study, series or frame of reference UID", dir);
  return s;
}

std::string ds(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

std::string new_uid(const char* root) {
  char uid[100];
  return dcmGenerateUniqueIdentifier(uid, root);
}

}  // namespace

StructureSet read_rtstruct(const std::string& path) {
  dicom::init_dcmtk();
  DcmFileFormat ff;
  check(ff.loadFile(path.c_str()), "cannot read the DICOM file", path);
  DRTStructureSetIOD rt;
  check(rt.read(*ff.getDataset()), "not an RT Structure Set", path);
  OFString value;
  require(text_of(rt.getModality(value), value) == "RTSTRUCT", "its Modality is '" + std::string(value.c_str()) +
                                                                   "', not RTSTRUCT",
          path, "give the structure set file of the CT");
  StructureSet set;
  std::map<Sint32, std::size_t> by_number;
  DRTStructureSetROISequence& rois = rt.getStructureSetROISequence();
  for (std::size_t n = 0; n < rois.getNumberOfItems(); ++n) {
    DRTStructureSetROISequence::Item& item = rois.getItem(n);
    StructureRoi roi;
    Sint32 number = 0;
    check(item.getROINumber(number), "an ROI has no ROI Number", path);
    roi.number = int(number);
    roi.name = text_of(item.getROIName(value), value);
    roi.frame_of_reference_uid = text_of(item.getReferencedFrameOfReferenceUID(value), value);
    by_number[number] = set.rois.size();
    set.rois.push_back(std::move(roi));
  }
  DRTROIContourSequence& contours = rt.getROIContourSequence();
  for (std::size_t n = 0; n < contours.getNumberOfItems(); ++n) {
    DRTROIContourSequence::Item& item = contours.getItem(n);
    Sint32 number = 0;
    check(item.getReferencedROINumber(number), "an ROI Contour item has no Referenced ROI Number", path);
    const auto found = by_number.find(number);
    require(found != by_number.end(),
            "contours of ROI number " + std::to_string(number) + ", which the Structure Set ROI Sequence does not define",
            path);
    StructureRoi& roi = set.rois[found->second];
    const std::string where = path + ", ROI '" + roi.name + "'";
    for (int c = 0; c < 3; ++c) {
      Sint32 channel = 0;
      if (item.getROIDisplayColor(channel, c).good()) roi.color[std::size_t(c)] = int(channel);
    }
    DRTContourSequence& seq = item.getContourSequence();
    for (std::size_t m = 0; m < seq.getNumberOfItems(); ++m) {
      DRTContourSequence::Item& contour = seq.getItem(m);
      const std::string which = "contour " + std::to_string(m + 1);
      const std::string type = text_of(contour.getContourGeometricType(value), value);
      require(type == "CLOSED_PLANAR", which + " has geometric type '" + type + "'; only CLOSED_PLANAR contours enclose voxels",
              where);
      OFVector<Float64> data;
      contour.getContourData(data);
      Sint32 points = -1;
      contour.getNumberOfContourPoints(points);
      require(data.size() % 3 == 0 && Sint32(data.size() / 3) == points,
              which + " is malformed: " + std::to_string(data.size()) + " Contour Data values for " +
                  std::to_string(points) + " points (3 per point expected)",
              where);
      std::vector<Eigen::Vector3d> polygon;
      for (std::size_t p = 0; p + 2 < data.size(); p += 3)
        polygon.emplace_back(data[p] / kMmPerM, data[p + 1] / kMmPerM, data[p + 2] / kMmPerM);
      if (polygon.size() > 1 && polygon.front() == polygon.back()) polygon.pop_back();  // an explicit closing point
      roi.contours.push_back(std::move(polygon));
    }
  }
  return set;
}

void write_rtstruct(const std::string& path, const StructureSet& set, const std::string& ct_series_dir,
                    const std::string& label, bool deterministic) {
  dicom::init_dcmtk();
  const ReferencedSeries ct = read_referenced_series(ct_series_dir);
  DRTStructureSetIOD rt;
  const auto put = [&](const OFCondition& status, const char* what) { check(status, std::string("cannot set ") + what, path); };
  char date[16] = "", clock[16] = "";  // Structure Set Date and Time are type 2: empty when deterministic
  if (!deterministic) {
    const std::time_t now = std::time(nullptr);
    std::strftime(date, sizeof date, "%Y%m%d", std::gmtime(&now));
    std::strftime(clock, sizeof clock, "%H%M%S", std::gmtime(&now));
  }
  // Deterministic UIDs are named after the referenced series (itself named after its content)
  // and the label, so the same structures on the same series give a byte-identical file.
  const auto uid = [&](const char* root, const char* role) {
    return deterministic ? dicom::name_based_uid(ct.series_uid + "/" + label + "/" + role) : new_uid(root);
  };
  put(rt.setPatientName(ct.patient_study.at(DCM_PatientName).c_str()), "PatientName");
  put(rt.setPatientID(ct.patient_study.at(DCM_PatientID).c_str()), "PatientID");
  put(rt.setPatientBirthDate(ct.patient_study.at(DCM_PatientBirthDate).c_str()), "PatientBirthDate");
  put(rt.setPatientSex(ct.patient_study.at(DCM_PatientSex).c_str()), "PatientSex");
  put(rt.setStudyInstanceUID(ct.study_uid.c_str()), "StudyInstanceUID");
  put(rt.setStudyDate(ct.patient_study.at(DCM_StudyDate).c_str()), "StudyDate");
  put(rt.setStudyTime(ct.patient_study.at(DCM_StudyTime).c_str()), "StudyTime");
  put(rt.setReferringPhysicianName(ct.patient_study.at(DCM_ReferringPhysicianName).c_str()), "ReferringPhysicianName");
  put(rt.setStudyID(ct.patient_study.at(DCM_StudyID).c_str()), "StudyID");
  put(rt.setFrameOfReferenceUID(ct.frame_uid.c_str()), "FrameOfReferenceUID");  // the Frame of Reference module
  put(rt.setPositionReferenceIndicator(""), "PositionReferenceIndicator");
  put(rt.setAccessionNumber(ct.patient_study.at(DCM_AccessionNumber).c_str()), "AccessionNumber");
  put(rt.setModality("RTSTRUCT"), "Modality");
  put(rt.setSeriesInstanceUID(uid(SITE_SERIES_UID_ROOT, "rtstruct series").c_str()), "SeriesInstanceUID");
  put(rt.setSeriesNumber("9001"), "SeriesNumber");
  put(rt.setSeriesDescription(label.c_str()), "SeriesDescription");
  put(rt.setOperatorsName(""), "OperatorsName");
  put(rt.setManufacturer("VoxBreast"), "Manufacturer");
  put(rt.setSoftwareVersions(config::version), "SoftwareVersions");
  put(rt.setSOPClassUID(UID_RTStructureSetStorage), "SOPClassUID");
  put(rt.setSOPInstanceUID(uid(SITE_INSTANCE_UID_ROOT, "rtstruct instance").c_str()), "SOPInstanceUID");
  put(rt.setInstanceNumber("1"), "InstanceNumber");
  put(rt.setStructureSetLabel(label.substr(0, 16).c_str()), "StructureSetLabel");
  put(rt.setStructureSetDate(date), "StructureSetDate");
  put(rt.setStructureSetTime(clock), "StructureSetTime");

  // The referenced frame, study, series and images.
  DRTReferencedFrameOfReferenceSequence::Item* frame = nullptr;
  put(rt.getReferencedFrameOfReferenceSequence().addItem(frame), "ReferencedFrameOfReferenceSequence");
  put(frame->setFrameOfReferenceUID(ct.frame_uid.c_str()), "FrameOfReferenceUID");
  DRTRTReferencedStudySequence::Item* study = nullptr;
  put(frame->getRTReferencedStudySequence().addItem(study), "RTReferencedStudySequence");
  put(study->setReferencedSOPClassUID(UID_RETIRED_DetachedStudyManagementSOPClass), "ReferencedSOPClassUID");
  put(study->setReferencedSOPInstanceUID(ct.study_uid.c_str()), "ReferencedSOPInstanceUID");
  DRTRTReferencedSeriesSequence::Item* series = nullptr;
  put(study->getRTReferencedSeriesSequence().addItem(series), "RTReferencedSeriesSequence");
  put(series->setSeriesInstanceUID(ct.series_uid.c_str()), "SeriesInstanceUID");
  for (const ReferencedImage& image : ct.images) {
    DRTContourImageSequence::Item* ref = nullptr;
    put(series->getContourImageSequence().addItem(ref), "ContourImageSequence");
    put(ref->setReferencedSOPClassUID(image.sop_class_uid.c_str()), "ReferencedSOPClassUID");
    put(ref->setReferencedSOPInstanceUID(image.sop_instance_uid.c_str()), "ReferencedSOPInstanceUID");
  }

  for (const StructureRoi& roi : set.rois) {
    const std::string number = std::to_string(roi.number);
    DRTStructureSetROISequence::Item* item = nullptr;
    put(rt.getStructureSetROISequence().addItem(item), "StructureSetROISequence");
    put(item->setROINumber(number.c_str()), "ROINumber");
    put(item->setReferencedFrameOfReferenceUID(ct.frame_uid.c_str()), "ReferencedFrameOfReferenceUID");
    put(item->setROIName(roi.name.c_str()), "ROIName");
    put(item->setROIGenerationAlgorithm("AUTOMATIC"), "ROIGenerationAlgorithm");

    DRTROIContourSequence::Item* contours = nullptr;
    put(rt.getROIContourSequence().addItem(contours), "ROIContourSequence");
    put(contours->setReferencedROINumber(number.c_str()), "ReferencedROINumber");
    const std::string color =
        std::to_string(roi.color[0]) + "\\" + std::to_string(roi.color[1]) + "\\" + std::to_string(roi.color[2]);
    put(contours->setROIDisplayColor(color.c_str()), "ROIDisplayColor");
    for (std::size_t c = 0; c < roi.contours.size(); ++c) {
      const std::vector<Eigen::Vector3d>& polygon = roi.contours[c];
      std::string data;
      for (const Eigen::Vector3d& p : polygon)
        for (int a = 0; a < 3; ++a) data += (data.empty() ? "" : "\\") + ds(kMmPerM * p[a]);
      DRTContourSequence::Item* contour = nullptr;
      put(contours->getContourSequence().addItem(contour), "ContourSequence");
      put(contour->setContourNumber(std::to_string(c + 1).c_str()), "ContourNumber");
      put(contour->setContourGeometricType("CLOSED_PLANAR"), "ContourGeometricType");
      put(contour->setNumberOfContourPoints(std::to_string(polygon.size()).c_str()), "NumberOfContourPoints");
      put(contour->setContourData(data.c_str(), OFFalse), "ContourData");
    }

    DRTRTROIObservationsSequence::Item* observation = nullptr;
    put(rt.getRTROIObservationsSequence().addItem(observation), "RTROIObservationsSequence");
    put(observation->setObservationNumber(number.c_str()), "ObservationNumber");
    put(observation->setReferencedROINumber(number.c_str()), "ReferencedROINumber");
    put(observation->setRTROIInterpretedType("ORGAN"), "RTROIInterpretedType");
    put(observation->setROIInterpreter(""), "ROIInterpreter");
  }

  DcmFileFormat ff;
  check(rt.write(*ff.getDataset()), "cannot build the RT Structure Set", path);
  AtomicOutput out(path);
  check(ff.saveFile(out.temp_path().c_str(), EXS_LittleEndianExplicit), "cannot write the file", path);
  out.commit();
}

}  // namespace vb
