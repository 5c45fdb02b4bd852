#pragma once
/// The volume lattice for viewers as VTK XML UnstructuredGrid (.vtu): every element is a point,
/// every complete dual cell a VTK_HEXAHEDRON (type 12) over its 8 elements, in VTK's corner
/// order. Coordinates are the DICOM LPS world frame in millimetres (3D Slicer's default). Atomic.
#include <span>
#include <string>
#include <vector>

#include "engine/lattice/lattice.hpp"
#include "io/element_field.hpp"

namespace vb {

/// Point data: `displacement_mm` (zero when `displacement_m` is empty), `tissue` (Int32 index into
/// lattice.tissue_names) and each field. Field data: one Int32 array per tissue, named by the
/// tissue, holding its `tissue` value (readable by meshio as well as VTK). Elements in no complete cell
/// (one-voxel strands) are points of no cell.
/// positions_m, displacement_m: n_elements × 3, world frame (m).
void write_lattice_vtu(const std::string& path, const Lattice& lattice, std::span<const double> positions_m,
                       std::span<const double> displacement_m = {}, const std::vector<ElementField>& fields = {});

}  // namespace vb
