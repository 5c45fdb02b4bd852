#pragma once
/// Reads a triangle surface from STL (binary or ASCII; millimetres in the DICOM LPS world frame,
/// as write_triangle_mesh_stl writes). Corners with equal coordinates become one vertex, so a
/// closed surface comes back closed. Strict: a truncated file, a triangle count that does not
/// match the file's size, a non-finite coordinate or an empty mesh is a vb::Error naming the file.
#include <string>

#include "engine/geometry/triangle_mesh.hpp"

namespace vb {

TriangleMesh read_stl(const std::string& path);

}  // namespace vb
