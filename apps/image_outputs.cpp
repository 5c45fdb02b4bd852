#include "apps/image_outputs.hpp"

#include <cmath>

#include "engine/image/deformation_field.hpp"
#include "io/dicom_io.hpp"
#include "io/nifti_io.hpp"

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

}  // namespace

nlohmann::json write_image_outputs(const std::string& dir, const Scene& scene, const Lattice& lattice,
                                   const ImageVolume& ct, const FinalState& state) {
  const OutputSpec& want = scene.output;
  nlohmann::json written = nlohmann::json::object();
  const LatticeField field(lattice, state.displacement_m);
  if (want.dvf) {
    write_nifti_displacement(dir + "/dvf.nii.gz", ct, forward_displacement_on_grid(field, ct));
    written["dvf"] = "dvf.nii.gz";
  }
  if (want.dvf || want.warped_ct || want.warped_ct_dicom) {
    const WarpResult warp = warp_image(ct, lattice, state.displacement_m);
    if (want.dvf) {
      write_nifti_displacement(dir + "/dvf_inverse.nii.gz", ct, warp.inverse_field);
      written["dvf_inverse"] = "dvf_inverse.nii.gz";
    }
    if (want.warped_ct) {
      write_nifti(dir + "/warped_ct.nii.gz", warp.warped, NiftiType::Int16);
      written["warped_ct"] = "warped_ct.nii.gz";
    }
    if (want.warped_ct_dicom) {
      replace_dicom_series(dir + "/warped_ct_dicom", warp.warped, "VoxBreast warped CT");  // a rerun replaces its own earlier series
      written["warped_ct_dicom"] = "warped_ct_dicom/";
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
