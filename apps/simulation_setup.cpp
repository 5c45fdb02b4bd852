#include "apps/simulation_setup.hpp"

#include <cstdio>
#include <filesystem>

#include "engine/error.hpp"
#include "engine/image/image_lattice.hpp"
#include "engine/image/structure_set.hpp"
#include "engine/lattice/voxelise.hpp"
#include "engine/sim/element_mass.hpp"
#include "engine/sim/device_memory.hpp"
#include "engine/sim/simulator.hpp"
#include "io/dicom_io.hpp"
#include "io/nifti_io.hpp"
#include "io/rtstruct.hpp"
#include "io/scene_file.hpp"
#include "io/scene_structures.hpp"

namespace vb::app {

Scene load_scene(const std::string& path, const std::string& precision) {
  Scene scene = parse_scene_file(path);
  if (precision == "double") scene.solver.precision = Precision::Double;
  if (precision == "float") scene.solver.precision = Precision::Float;
  return scene;
}

ImageVolume load_ct(const ModelSpec& model, std::vector<std::string>& warnings) {
  if (std::filesystem::is_directory(model.image_path))
    return read_dicom_series(model.image_path, model.series_uid, model.allow_gaps, &warnings);
  return read_nifti(model.image_path);
}

namespace {

/// Moduli below the softest tissue's (~0.3 kPa for fat at small strain) are almost surely kPa
/// written where pascals belong; such a model sags without bound, so say why up front.
void warn_implausible_moduli(const Scene& scene, const Lattice& lattice, std::vector<std::string>& warnings) {
  constexpr double kSoftestTissuePa = 100;
  for (const std::string& tissue : lattice.tissue_names) {
    const auto it = scene.materials.find(tissue);
    if (it == scene.materials.end()) continue;
    const MaterialSpec& m = it->second;
    if (m.rigid || !m.law_takes_E() || m.youngs_modulus_pa >= kSoftestTissuePa) continue;
    char text[240];
    std::snprintf(text, sizeof text,
                  "materials.%s.E = %g Pa is below any soft tissue's modulus (100 Pa): E is in pascals (%g kPa is %g)",
                  tissue.c_str(), m.youngs_modulus_pa, m.youngs_modulus_pa, m.youngs_modulus_pa * 1e3);
    warnings.push_back(text);
  }
}

/// Hyperelastic tissue carries the mass of the hull of its element centres (docs/PHYSICS.md,
/// "Mass"): say so where that drops more than half of a tissue's voxel mass (sheets or strands
/// about two voxels thick or less), and where elements with no complete dual cell get the floor.
void warn_lumped_mass(const Scene& scene, const Lattice& lattice, const ElementArrays& el,
                      std::vector<std::string>& warnings) {
  constexpr double kMassLossWarning = 0.5;
  const std::vector<TissueMass> masses = tissue_masses(scene, lattice, el);
  for (std::size_t t = 0; t < masses.size(); ++t) {
    const TissueMass& m = masses[t];
    if (!m.hull_body) continue;
    const char* name = lattice.tissue_names[t].c_str();
    char text[400];
    if (m.floored > 0) {
      std::snprintf(text, sizeof text,
                    "tissue '%s' (hyperelastic): %zu of its %zu elements have no complete dual cell around them "
                    "(one-voxel strands or sheets, or isolated elements), so no elastic volume; each is given %g of a "
                    "voxel's mass",
                    name, m.floored, m.elements, kLeastVolumeFraction);
      warnings.push_back(text);
    }
    const double loss = 1 - m.model_kg / m.voxel_kg;
    if (loss > kMassLossWarning) {
      std::snprintf(text, sizeof text,
                    "tissue '%s' (hyperelastic) carries %.4g kg, %.0f%% less than its voxels (%.4g kg): its body is the "
                    "hull of the element centres, and most of it is thinner than about two voxels",
                    name, m.model_kg, 100 * loss, m.voxel_kg);
      warnings.push_back(text);
    }
  }
}

/// model.structures rasterised on the CT: each ROI the table maps to a tissue gets a label value
/// (1, 2, … in the file's order), which model.label_table maps to its tissue; names: value → ROI.
ImageVolume structure_labels(const StructureSpec& structures, const ImageVolume& ct, ModelSpec& model,
                             std::map<int, std::string>& names) {
  const StructureSet set = read_rtstruct(structures.path);
  StructureLabelRule rule;
  rule.priority = structures.priority;
  for (const StructureRoi& roi : set.rois) {
    const auto tissue = structures.table.find(roi.name);
    if (tissue == structures.table.end()) continue;  // rasterise_structures names it
    if (tissue->second == "ignore") {
      rule.labels[roi.name] = 0;
      continue;
    }
    const int value = int(names.size()) + 1;
    rule.labels[roi.name] = value;
    names[value] = roi.name;
    model.label_table[value] = tissue->second;
  }
  for (const auto& [roi, tissue] : structures.table)
    require(rule.labels.count(roi), "the structure table names ROI '" + roi + "', which the RTSTRUCT does not hold",
            structures.path, "check the ROI names in the file");
  return rasterise_structures(set, ct, rule);
}

}  // namespace

PreparedModel prepare_model(const Scene& scene, const DeviceInfo* device) {
  PreparedModel m;
  MemoryBudget budget;  // checked before the voxel grid is allocated
  budget.host_bytes = available_host_memory_bytes();
  if (device) {
    budget.device_bytes = device->global_memory_bytes;
    budget.device_name = device->name;
  }
  if (scene.model.from_image()) {
    m.ct = load_ct(scene.model, m.warnings);
    ModelSpec model = scene.model;
    if (!model.labels_path.empty()) {
      m.labels = read_nifti(model.labels_path);
      m.label_names = model.label_table;
    } else if (const StructureSpec structures = scene_structures(scene); !structures.path.empty()) {
      m.labels = structure_labels(structures, *m.ct, model, m.label_names);
    }
    const TissueMap map = classify_image(model, *m.ct, m.labels ? &*m.labels : nullptr);
    m.lattice = build_lattice(lattice_volume_from_image(model, *m.ct, map, scene.solver.precision, budget),
                              scene.model.downsample);
  } else {
    m.lattice = build_lattice(voxelise_shapes(scene, budget), scene.model.downsample);
  }
  if (device) check_lattice_fits_device(scene, m.lattice, *device);
  m.elements = make_element_arrays(scene, m.lattice);
  warn_implausible_moduli(scene, m.lattice, m.warnings);
  warn_lumped_mass(scene, m.lattice, m.elements, m.warnings);
  return m;
}

}  // namespace vb::app
