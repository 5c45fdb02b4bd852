#include "io/vtk_xml_arrays.hpp"

#include <algorithm>
#include <bit>
#include <cstring>

namespace vb::vtk_xml {

static_assert(std::endian::native == std::endian::little, "the VTK writers emit the host's bytes as LittleEndian");

std::string base64(const void* data, std::size_t bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* p = static_cast<const unsigned char*>(data);
  std::string out;
  out.reserve((bytes + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes; i += 3) {
    const std::size_t n = std::min<std::size_t>(3, bytes - i);
    const std::uint32_t v = std::uint32_t(p[i]) << 16 | (n > 1 ? std::uint32_t(p[i + 1]) << 8 : 0u) | (n > 2 ? p[i + 2] : 0u);
    out += kAlphabet[v >> 18 & 63];
    out += kAlphabet[v >> 12 & 63];
    out += n > 1 ? kAlphabet[v >> 6 & 63] : '=';
    out += n > 2 ? kAlphabet[v & 63] : '=';
  }
  return out;
}

template <> const char* type_name<double>() { return "Float64"; }
template <> const char* type_name<float>() { return "Float32"; }
template <> const char* type_name<std::int64_t>() { return "Int64"; }
template <> const char* type_name<std::int32_t>() { return "Int32"; }
template <> const char* type_name<std::uint8_t>() { return "UInt8"; }

template <class T>
std::string data_array(const std::string& name, int components, const std::vector<T>& values) {
  // Uncompressed inline binary: one base64 stream of the UInt64 byte count then the values.
  const std::uint64_t bytes = values.size() * sizeof(T);
  std::vector<unsigned char> block(sizeof bytes + bytes);
  std::memcpy(block.data(), &bytes, sizeof bytes);
  if (bytes) std::memcpy(block.data() + sizeof bytes, values.data(), bytes);
  std::string out = std::string("<DataArray type=\"") + type_name<T>() + "\"";
  if (!name.empty()) out += " Name=\"" + escape_attribute(name) + "\"";
  if (components != 1) out += " NumberOfComponents=\"" + std::to_string(components) + "\"";
  out += " format=\"binary\">" + base64(block.data(), block.size()) + "</DataArray>\n";
  return out;
}

template std::string data_array(const std::string&, int, const std::vector<double>&);
template std::string data_array(const std::string&, int, const std::vector<float>&);
template std::string data_array(const std::string&, int, const std::vector<std::int64_t>&);
template std::string data_array(const std::string&, int, const std::vector<std::int32_t>&);
template std::string data_array(const std::string&, int, const std::vector<std::uint8_t>&);

namespace {

/// An ASCII string array: each string as its character codes, each ended by 0 (VTK's layout).
std::string string_array(const std::string& name, const std::vector<std::string>& strings) {
  std::string codes;
  for (const std::string& s : strings) {
    for (const unsigned char ch : s) codes += std::to_string(int(ch)) + " ";
    codes += "0 ";
  }
  if (!codes.empty()) codes.pop_back();
  return "<Array type=\"String\" Name=\"" + escape_attribute(name) + "\" NumberOfTuples=\"" +
         std::to_string(strings.size()) + "\" format=\"ascii\">" + codes + "</Array>\n";
}

}  // namespace

std::string field_data() { return "<FieldData>\n" + string_array("SPACE", {"LPS"}) + "</FieldData>\n"; }

std::string escape_attribute(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace vb::vtk_xml
