#include "apps/image_outputs.hpp"

#include <cmath>

#include "engine/image/deformation_field.hpp"
#include "engine/image/displacement_stats.hpp"
#include "engine/image/source_slices.hpp"
#include "io/dicom_io.hpp"
#include "io/metaimage_io.hpp"
#include "io/nifti_io.hpp"
#include "io/scene_file.hpp"

namespace vb::app {
namespace {

std::vector<double> displacement_norm_mm(const FinalState& s) {
  std::vector<double> out(s.displacement_m.size() / 3);
  for (std::size_t e = 0; e < out.size(); ++e)
    out[e] = 1e3 * std::sqrt(s.displacement_m[3 * e] * s.displacement_m[3 * e] +
                             s.displacement_m[3 * e + 1] * s.displacement_m[3 * e + 1] +
                             s.displacement_m[3 * e + 2] * s.displacement_m[3 * e + 2]);
  return out;
}

/// A DVF as NIfTI (in the scene's layout) and as MetaImage; its statistics for summary.json.
void write_dvf(const std::string& dir, const std::string& name, const ImageVolume& grid, const std::vector<float>& u,
               const DvfFileOptions& files, nlohmann::json& written) {
  write_nifti_displacement(dir + "/" + name + ".nii.gz", grid, u,
                           files.legacy_nifti ? NiftiDisplacementLayout::VectorLps : NiftiDisplacementLayout::DispVectRas);
  write_metaimage_displacement(dir + "/" + name + ".mha", grid, u);
  written[name] = name + ".nii.gz";
  written[name + "_mha"] = name + ".mha";
  const DisplacementStats s = displacement_stats(u);
  written[name + "_stats_mm"] = {{"min", s.min_mm},           {"max", s.max_mm},
                                 {"mean", s.mean_mm},         {"mean_abs", s.mean_abs_mm},
                                 {"mean_length", s.mean_length_mm}, {"max_length", s.max_length_mm}};
}

}  // namespace

nlohmann::json write_image_outputs(const std::string& dir, const Scene& scene, const Lattice& lattice,
                                   const ImageVolume& ct, const FinalState& state) {
  const OutputSpec& want = scene.output;
  nlohmann::json written = nlohmann::json::object();
  const LatticeField field(lattice, state.displacement_m);
  const DvfFileOptions files = dvf_file_options(scene);
  if (want.dvf) write_dvf(dir, "dvf", ct, forward_displacement_on_grid(field, ct), files, written);
  if (want.dvf || want.warped_ct || want.warped_ct_dicom) {
    const WarpResult warp = warp_image(ct, lattice, state.displacement_m);
    if (want.dvf) write_dvf(dir, "dvf_inverse", ct, warp.inverse_field, files, written);
    if (want.warped_ct) {
      write_nifti(dir + "/warped_ct.nii.gz", warp.warped, NiftiType::Int16);
      written["warped_ct"] = "warped_ct.nii.gz";
    }
    if (want.warped_ct_dicom) {
      DicomSeriesOptions series;
      series.series_description = "VoxBreast warped CT";
      series.patient_position = dicom_patient_position(scene.gravity.active ? scene.gravity.acceleration_m_s2 : Vec3::Zero());
      if (!ct.dicom_tags.empty()) series.source_slices = source_slices_read(ct, warp.inverse_field);
      // a rerun replaces its own earlier series
      const WrittenDicomSeries warped = replace_dicom_series(dir + "/warped_ct_dicom", warp.warped, series);
      written["warped_ct_dicom"] = "warped_ct_dicom/";
      if (files.dicom) {
        write_dicom_deformable_registration(dir + "/dvf_inverse.dcm", ct, warp.inverse_field, ct, warped);
        written["dvf_inverse_dicom"] = "dvf_inverse.dcm";
      }
    }
    written["warp_vacated_voxels"] = warp.vacated_voxels;
    written["warp_max_inversion_residual_m"] = warp.max_fixed_point_residual_m;
  }
  if (want.fields) {
    std::vector<double> tissue(lattice.element_count());
    for (std::size_t e = 0; e < tissue.size(); ++e) tissue[e] = lattice.tissue_of_element[e] + 1;
    write_nifti(dir + "/model_labels.nii.gz", rasterise_elements(field, ct, tissue, 0.f), NiftiType::UInt8);
    write_nifti(dir + "/displacement_mm.nii.gz", rasterise_elements(field, ct, displacement_norm_mm(state), 0.f),
                NiftiType::Float32);
    write_nifti(dir + "/equivalent_strain.nii.gz", rasterise_elements(field, ct, state.equivalent_strain, 0.f),
                NiftiType::Float32);
    write_nifti(dir + "/von_mises_stress_pa.nii.gz", rasterise_elements(field, ct, state.von_mises_stress_pa, 0.f),
                NiftiType::Float32);
    nlohmann::json names = nlohmann::json::object();
    for (std::size_t t = 0; t < lattice.tissue_names.size(); ++t) names[std::to_string(t + 1)] = lattice.tissue_names[t];
    written["model_labels"] = {{"file", "model_labels.nii.gz"}, {"values", names}};
    written["fields"] = {"displacement_mm.nii.gz", "equivalent_strain.nii.gz", "von_mises_stress_pa.nii.gz"};
  }
  return written;
}

}  // namespace vb::app
