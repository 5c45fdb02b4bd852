#pragma once
/// CT image → tissue-labelled voxel volume on the lattice grid: classify (label volume + table,
/// or HU classes), keep only the tissues and region the scene asks for, and resample to an
/// isotropic grid aligned with the image axes (oblique CTs keep their orientation).
#include "engine/image/image_volume.hpp"
#include "engine/lattice/lattice.hpp"
#include "engine/lattice/model_memory.hpp"
#include "engine/scene/scene.hpp"

namespace vb {

/// Tissue index per CT voxel (0 = not modelled, t ≥ 1 = tissue_names[t − 1]).
struct TissueMap {
  std::vector<std::uint8_t> tissue;  ///< on the CT grid
  std::vector<std::string> tissue_names;
};

/// Classifies every CT voxel. `labels` (same grid as ct) is used with model.label_table,
/// otherwise model.hu_classes on the CT values. Tissues outside model.keep (when given) and
/// voxels outside model.roi_m are dropped. Throws vb::Error when nothing is left.
TissueMap classify_image(const ModelSpec& model, const ImageVolume& ct, const ImageVolume* labels);

/// Resamples the classified image onto an isotropic grid of spacing model.spacing_m (0: the
/// image's largest spacing), aligned with the image axes, cropped to the modelled voxels.
/// Nearest-neighbour: each lattice voxel takes the tissue of the CT voxel containing its centre.
/// A grid of 2^31 voxels or more, or a model whose estimated memory (`precision` on the device)
/// exceeds `budget`, is refused before the grid is allocated.
LabelVolume lattice_volume_from_image(const ModelSpec& model, const ImageVolume& ct, const TissueMap& map,
                                      Precision precision = Precision::Float, const MemoryBudget& budget = {});

}  // namespace vb
