#pragma once
/// Pieces of VTK XML files (.vtp, .vtu) shared by the mesh writers: inline base64 binary data
/// arrays and the field data that names the coordinate system. Format: "VTK File Formats", XML
/// section (kitware.com); version 0.1 files with header_type UInt64: each binary array is
/// base64(UInt64 byte count + little-endian values), and cell offsets are end offsets.
#include <cstdint>
#include <string>
#include <vector>

namespace vb::vtk_xml {

std::string base64(const void* data, std::size_t bytes);

/// VTK's name for a value type ("Float64", "Int64", ...).
template <class T>
const char* type_name();

/// `<DataArray type=... Name=... NumberOfComponents=... format="binary">…</DataArray>\n`;
/// the name is left out when empty (points).
template <class T>
std::string data_array(const std::string& name, int components, const std::vector<T>& values);

/// `<FieldData>` with SPACE = "LPS" (3D Slicer reads it: coordinates are DICOM LPS).
std::string field_data();

/// Escapes &, <, >, " for an attribute value.
std::string escape_attribute(const std::string& text);

}  // namespace vb::vtk_xml
