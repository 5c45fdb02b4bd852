#include "io/triangle_mesh_files.hpp"

#include <Eigen/Geometry>

#include "engine/error.hpp"
#include "engine/surface/surface_mesh.hpp"
#include "io/atomic_file.hpp"
#include "io/surface_mesh_files.hpp"
#include "io/vtk_xml_arrays.hpp"

namespace vb {
namespace {

constexpr double kMmPerM = 1000.0;

void check_mesh(const std::string& path, const TriangleMesh& mesh) {
  for (const auto& t : mesh.triangles)
    for (const std::uint32_t v : t)
      require(v < mesh.vertices_m.size(), "a triangle refers to vertex " + std::to_string(v) + " beyond the mesh", path);
}

}  // namespace

void write_triangle_mesh_vtp(const std::string& path, const TriangleMesh& mesh) {
  check_mesh(path, mesh);
  const std::size_t nv = mesh.vertices_m.size(), nt = mesh.triangles.size();
  std::vector<double> points(3 * nv);
  std::vector<Eigen::Vector3d> normal_sum(nv, Eigen::Vector3d::Zero());
  for (const auto& t : mesh.triangles) {  // the cross product is twice the area: area-weighted
    const Eigen::Vector3d& a = mesh.vertices_m[t[0]];
    const Eigen::Vector3d n = (mesh.vertices_m[t[1]] - a).cross(mesh.vertices_m[t[2]] - a);
    for (const std::uint32_t v : t) normal_sum[v] += n;
  }
  std::vector<float> normals(3 * nv, 0.0f);
  for (std::size_t v = 0; v < nv; ++v) {
    const double length = normal_sum[v].norm();
    for (int c = 0; c < 3; ++c) {
      points[3 * v + c] = kMmPerM * mesh.vertices_m[v][c];
      if (length > 0) normals[3 * v + c] = float(normal_sum[v][c] / length);
    }
  }
  std::vector<std::int64_t> connectivity(3 * nt), offsets(nt);
  for (std::size_t t = 0; t < nt; ++t) {
    for (int k = 0; k < 3; ++k) connectivity[3 * t + k] = mesh.triangles[t][k];
    offsets[t] = std::int64_t(3 * (t + 1));  // end offsets (file version 0.1)
  }
  using vtk_xml::data_array;
  const std::string xml =
      "<?xml version=\"1.0\"?>\n"
      "<!-- VoxBreast device mesh: DICOM LPS world frame, millimetres -->\n"
      "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
      "<PolyData>\n" +
      vtk_xml::field_data() + "<Piece NumberOfPoints=\"" + std::to_string(nv) +
      "\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"" + std::to_string(nt) +
      "\">\n<PointData Normals=\"Normals\">\n" + data_array("Normals", 3, normals) + "</PointData>\n<Points>\n" +
      data_array("", 3, points) + "</Points>\n<Polys>\n" + data_array("connectivity", 1, connectivity) +
      data_array("offsets", 1, offsets) + "</Polys>\n</Piece>\n</PolyData>\n</VTKFile>\n";
  write_text_atomically(path, xml);
}

void write_triangle_mesh_stl(const std::string& path, const TriangleMesh& mesh) {
  check_mesh(path, mesh);
  // The breast-surface STL writer with each vertex standing for itself.
  SurfaceMesh as_surface;
  as_surface.triangles = mesh.triangles;
  as_surface.element_of_vertex.resize(mesh.vertices_m.size());
  std::vector<double> positions(3 * mesh.vertices_m.size());
  for (std::size_t v = 0; v < mesh.vertices_m.size(); ++v) {
    as_surface.element_of_vertex[v] = std::uint32_t(v);
    for (int c = 0; c < 3; ++c) positions[3 * v + c] = mesh.vertices_m[v][c];
  }
  write_surface_stl(path, as_surface, positions);
}

}  // namespace vb
