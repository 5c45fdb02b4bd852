#pragma once
/// Analytic shapes → labelled voxel volume.
#include "engine/lattice/lattice.hpp"
#include "engine/lattice/model_memory.hpp"
#include "engine/scene/scene.hpp"

namespace vb {

/// Voxelises the scene's shapes at model.spacing_m. Voxel centres sit at (n + ½)·h on a world-
/// aligned grid; a voxel takes the label of the last shape containing its centre. Tissue names
/// are the shapes' labels in order of first appearance. Shapes beyond 100 m from the origin, a
/// grid of 2^31 voxels or more, and a model whose estimated memory exceeds `budget` are refused
/// before the grid is allocated.
LabelVolume voxelise_shapes(const Scene& scene, const MemoryBudget& budget = {});

}  // namespace vb
