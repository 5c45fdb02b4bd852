#include "io/surface_mesh_files.hpp"

#include <Eigen/Geometry>
#include <cstring>

#include "engine/error.hpp"
#include "io/atomic_file.hpp"
#include "io/vtk_xml_arrays.hpp"

namespace vb {
namespace {

constexpr double kMmPerM = 1000.0;

void check_inputs(const std::string& path, const SurfaceMesh& mesh, std::span<const double> positions_m,
                  std::span<const double> displacement_m, const std::vector<ElementField>& fields) {
  require(positions_m.size() % 3 == 0, "positions must be n_elements × 3", path);
  const std::size_t n = positions_m.size() / 3;
  for (const std::uint32_t e : mesh.element_of_vertex)
    require(e < n, "the surface mesh refers to element " + std::to_string(e) + " beyond the positions", path);
  require(displacement_m.empty() || displacement_m.size() == positions_m.size(),
          "displacement must be n_elements × 3 like the positions", path);
  for (const ElementField& f : fields)
    require(f.components >= 1 && f.values.size() == n * std::size_t(f.components),
            "field '" + f.name + "' must have n_elements × " + std::to_string(f.components) + " values", path);
}

Eigen::Vector3d vertex_position_mm(const SurfaceMesh& mesh, std::span<const double> x, std::uint32_t v) {
  const std::size_t e = mesh.element_of_vertex[v];
  return kMmPerM * Eigen::Vector3d(x[3 * e], x[3 * e + 1], x[3 * e + 2]);
}

Eigen::Vector3d unit_or_zero(const Eigen::Vector3d& v) {
  const double n = v.norm();
  return n > 0 ? Eigen::Vector3d(v / n) : Eigen::Vector3d::Zero();
}

template <class T>
void append_bytes(std::string& out, const T& value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

}  // namespace

void write_surface_vtp(const std::string& path, const SurfaceMesh& mesh, std::span<const double> positions_m,
                       std::span<const double> displacement_m, const std::vector<ElementField>& fields) {
  check_inputs(path, mesh, positions_m, displacement_m, fields);
  const std::size_t nv = mesh.vertex_count(), nt = mesh.triangles.size();

  std::vector<double> points(3 * nv), displacement(3 * nv, 0.0);
  std::vector<float> normals(3 * nv, 0.0f);
  std::vector<std::int32_t> element(nv);
  std::vector<Eigen::Vector3d> normal_sum(nv, Eigen::Vector3d::Zero());
  for (const auto& t : mesh.triangles) {  // area-weighted: the cross product is twice the area
    const Eigen::Vector3d a = vertex_position_mm(mesh, positions_m, t[0]);
    const Eigen::Vector3d n = (vertex_position_mm(mesh, positions_m, t[1]) - a)
                                  .cross(vertex_position_mm(mesh, positions_m, t[2]) - a);
    for (const std::uint32_t v : t) normal_sum[v] += n;
  }
  for (std::size_t v = 0; v < nv; ++v) {
    const std::size_t e = mesh.element_of_vertex[v];
    element[v] = std::int32_t(e);
    const Eigen::Vector3d n = unit_or_zero(normal_sum[v]);
    for (int c = 0; c < 3; ++c) {
      points[3 * v + c] = kMmPerM * positions_m[3 * e + c];
      if (!displacement_m.empty()) displacement[3 * v + c] = kMmPerM * displacement_m[3 * e + c];
      normals[3 * v + c] = float(n[c]);
    }
  }
  std::vector<std::int64_t> connectivity(3 * nt), offsets(nt);
  for (std::size_t t = 0; t < nt; ++t) {
    for (int k = 0; k < 3; ++k) connectivity[3 * t + k] = mesh.triangles[t][k];
    offsets[t] = std::int64_t(3 * (t + 1));  // end offsets (file version 0.1)
  }

  using vtk_xml::data_array;
  std::string xml =
      "<?xml version=\"1.0\"?>\n"
      "<!-- VoxBreast surface mesh: DICOM LPS world frame, millimetres -->\n"
      "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
      "<PolyData>\n" +
      vtk_xml::field_data() + "<Piece NumberOfPoints=\"" + std::to_string(nv) +
      "\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"" + std::to_string(nt) +
      "\">\n<PointData Vectors=\"displacement_mm\" Normals=\"Normals\">\n" +
      data_array("displacement_mm", 3, displacement) + data_array("Normals", 3, normals) +
      data_array("element", 1, element);
  for (const ElementField& f : fields) {
    std::vector<double> values(nv * std::size_t(f.components));
    for (std::size_t v = 0; v < nv; ++v)
      for (int c = 0; c < f.components; ++c)
        values[v * std::size_t(f.components) + std::size_t(c)] =
            f.values[std::size_t(mesh.element_of_vertex[v]) * std::size_t(f.components) + std::size_t(c)];
    xml += data_array(f.name, f.components, values);
  }
  xml += "</PointData>\n<Points>\n" + data_array("", 3, points) + "</Points>\n<Polys>\n" +
         data_array("connectivity", 1, connectivity) + data_array("offsets", 1, offsets) +
         "</Polys>\n</Piece>\n</PolyData>\n</VTKFile>\n";
  write_text_atomically(path, xml);
}

void write_surface_ply(const std::string& path, const SurfaceMesh& mesh, std::span<const double> positions_m) {
  check_inputs(path, mesh, positions_m, {}, {});
  const std::size_t nv = mesh.vertex_count(), nt = mesh.triangles.size();
  require(nv < 0x7fffffffu, "too many vertices for PLY int32 indices", path);
  std::string out =
      "ply\nformat binary_little_endian 1.0\ncomment VoxBreast surface mesh\ncomment SPACE=LPS\n"
      "comment units mm\nelement vertex " + std::to_string(nv) +
      "\nproperty float x\nproperty float y\nproperty float z\nelement face " + std::to_string(nt) +
      "\nproperty list uchar int vertex_indices\nend_header\n";
  out.reserve(out.size() + 12 * nv + 13 * nt);
  for (std::uint32_t v = 0; v < nv; ++v) {
    const Eigen::Vector3d p = vertex_position_mm(mesh, positions_m, v);
    for (int c = 0; c < 3; ++c) append_bytes(out, float(p[c]));
  }
  for (const auto& t : mesh.triangles) {
    append_bytes(out, std::uint8_t(3));
    for (const std::uint32_t v : t) append_bytes(out, std::int32_t(v));
  }
  write_text_atomically(path, out);
}

void write_surface_stl(const std::string& path, const SurfaceMesh& mesh, std::span<const double> positions_m) {
  check_inputs(path, mesh, positions_m, {}, {});
  require(mesh.triangles.size() < 0xffffffffu, "too many triangles for STL", path);
  // The 80-byte header must not start with "solid" (readers would take the file for ASCII STL).
  std::string header = "VoxBreast surface mesh SPACE=LPS units=mm";
  header.resize(80, ' ');
  std::string out = header;
  out.reserve(84 + 50 * mesh.triangles.size());
  append_bytes(out, std::uint32_t(mesh.triangles.size()));
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = vertex_position_mm(mesh, positions_m, t[0]);
    const Eigen::Vector3d b = vertex_position_mm(mesh, positions_m, t[1]);
    const Eigen::Vector3d c = vertex_position_mm(mesh, positions_m, t[2]);
    const Eigen::Vector3d n = unit_or_zero((b - a).cross(c - a));
    for (const Eigen::Vector3d* p : {&n, &a, &b, &c})
      for (int k = 0; k < 3; ++k) append_bytes(out, float((*p)[k]));
    append_bytes(out, std::uint16_t(0));
  }
  write_text_atomically(path, out);
}

}  // namespace vb
