#include "io/lattice_vtu.hpp"

#include "engine/error.hpp"
#include "engine/lattice/dual_hexahedra.hpp"
#include "io/atomic_file.hpp"
#include "io/vtk_xml_arrays.hpp"

namespace vb {
namespace {

/// One Int32 field-data array per tissue, named by the tissue and holding its `tissue` value:
/// numbers, which meshio reads as well as VTK (meshio refuses VTK's String arrays). No SPACE
/// string either, for the same reason: 3D Slicer reads a file without it as LPS, its default.
std::string tissue_field_data(const std::vector<std::string>& tissue_names) {
  std::string out = "<FieldData>\n";
  for (std::size_t t = 0; t < tissue_names.size(); ++t)
    out += "<Array type=\"Int32\" Name=\"" + vtk_xml::escape_attribute(tissue_names[t]) +
           "\" NumberOfTuples=\"1\" format=\"ascii\">" + std::to_string(t) + "</Array>\n";
  return out + "</FieldData>\n";
}

}  // namespace

void write_lattice_vtu(const std::string& path, const Lattice& lattice, std::span<const double> positions_m,
                       std::span<const double> displacement_m, const std::vector<ElementField>& fields) {
  const std::size_t n = lattice.element_count();
  require(positions_m.size() == 3 * n, "positions must be n_elements × 3", path);
  require(displacement_m.empty() || displacement_m.size() == 3 * n, "displacement must be n_elements × 3", path);
  for (const ElementField& f : fields)
    require(f.components >= 1 && f.values.size() == n * std::size_t(f.components),
            "field '" + f.name + "' must have n_elements × " + std::to_string(f.components) + " values", path);

  std::vector<double> points(3 * n), displacement(3 * n, 0.0);
  std::vector<std::int32_t> tissue(n);
  for (std::size_t i = 0; i < 3 * n; ++i) {
    points[i] = 1000.0 * positions_m[i];
    if (!displacement_m.empty()) displacement[i] = 1000.0 * displacement_m[i];
  }
  for (std::size_t e = 0; e < n; ++e) tissue[e] = lattice.tissue_of_element[e];

  // VTK's hexahedron order is the dual cells' (engine/lattice/dual_hexahedra.hpp)
  std::vector<std::int64_t> connectivity, offsets;
  for (const auto& hex : dual_hexahedra(lattice)) {
    connectivity.insert(connectivity.end(), hex.begin(), hex.end());
    offsets.push_back(std::int64_t(connectivity.size()));
  }
  const std::vector<std::uint8_t> types(offsets.size(), 12);  // VTK_HEXAHEDRON

  using vtk_xml::data_array;
  std::string xml =
      "<?xml version=\"1.0\"?>\n"
      "<!-- VoxBreast lattice: elements as points, complete dual cells as hexahedra; SPACE=LPS, mm -->\n"
      "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
      "<UnstructuredGrid>\n" +
      tissue_field_data(lattice.tissue_names) + "<Piece NumberOfPoints=\"" + std::to_string(n) +
      "\" NumberOfCells=\"" + std::to_string(offsets.size()) + "\">\n<PointData Vectors=\"displacement_mm\">\n" +
      data_array("displacement_mm", 3, displacement) + data_array("tissue", 1, tissue);
  for (const ElementField& f : fields) xml += data_array(f.name, f.components, std::vector<double>(f.values.begin(), f.values.end()));
  xml += "</PointData>\n<Points>\n" + data_array("", 3, points) + "</Points>\n<Cells>\n" +
         data_array("connectivity", 1, connectivity) + data_array("offsets", 1, offsets) +
         data_array("types", 1, types) + "</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  write_text_atomically(path, xml);
}

}  // namespace vb
