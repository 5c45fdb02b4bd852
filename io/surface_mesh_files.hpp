#pragma once
/// Surface meshes for viewers: VTK XML PolyData (.vtp: ParaView, 3D Slicer) with per-vertex
/// arrays, binary PLY and binary STL. Coordinates are the DICOM LPS world frame in millimetres
/// (the viewers' convention; the files say SPACE=LPS the way 3D Slicer reads it). Every file
/// appears atomically. Layout and arrays: docs/SURFACE.md, "Files".
#include <span>
#include <string>
#include <vector>

#include "engine/surface/surface_mesh.hpp"
#include "io/element_field.hpp"

namespace vb {

/// .vtp: points = element positions of the mesh vertices, triangles as polys. Point data:
/// `displacement_mm` (3 components, zero when `displacement_m` is empty), `Normals` (unit,
/// of the written positions, area-weighted), `element` (the element index of each vertex) and
/// each field mapped to the vertices through mesh.element_of_vertex.
/// positions_m, displacement_m: n_elements × 3, world frame (m), e.g. element_positions_m().
void write_surface_vtp(const std::string& path, const SurfaceMesh& mesh, std::span<const double> positions_m,
                       std::span<const double> displacement_m = {}, const std::vector<ElementField>& fields = {});

/// Binary little-endian PLY: vertex x, y, z (float32, mm) and faces (uchar count, int32 ids).
void write_surface_ply(const std::string& path, const SurfaceMesh& mesh, std::span<const double> positions_m);

/// Binary STL: one facet per triangle (float32, mm) with its unit normal.
void write_surface_stl(const std::string& path, const SurfaceMesh& mesh, std::span<const double> positions_m);

}  // namespace vb
