#pragma once
/// Plain triangle meshes (device parts) for viewers, in the same convention as the breast surface
/// (io/surface_mesh_files.hpp): DICOM LPS world frame in millimetres, written atomically.
#include <string>

#include "engine/geometry/triangle_mesh.hpp"

namespace vb {

/// .vtp with the points, the triangles and per-point unit `Normals` (area-weighted).
void write_triangle_mesh_vtp(const std::string& path, const TriangleMesh& mesh);

/// Binary STL: one facet per triangle (float32, mm) with its unit normal.
void write_triangle_mesh_stl(const std::string& path, const TriangleMesh& mesh);

}  // namespace vb
