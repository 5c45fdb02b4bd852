#include "io/stl_file.hpp"

#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>

#include "engine/error.hpp"

namespace vb {
namespace {

constexpr double kMPerMm = 1e-3;

/// Welds corners by exact coordinates (STL repeats each shared corner per facet).
class Welder {
 public:
  explicit Welder(const std::string& path) : path_(path) {}
  void add_triangle(const std::array<std::array<double, 3>, 3>& corners, std::size_t facet) {
    std::array<std::uint32_t, 3> ids{};
    for (int k = 0; k < 3; ++k) {
      for (const double x : corners[std::size_t(k)])
        require(std::isfinite(x), "facet " + std::to_string(facet + 1) + " has a coordinate that is not a finite number",
                path_, "export the surface again");
      const auto [it, added] = ids_.try_emplace(corners[std::size_t(k)], std::uint32_t(mesh.vertices_m.size()));
      if (added) {
        const auto& c = corners[std::size_t(k)];
        mesh.vertices_m.emplace_back(c[0] * kMPerMm, c[1] * kMPerMm, c[2] * kMPerMm);
      }
      ids[std::size_t(k)] = it->second;
    }
    mesh.triangles.push_back(ids);
  }
  TriangleMesh mesh;

 private:
  std::string path_;
  std::map<std::array<double, 3>, std::uint32_t> ids_;
};

TriangleMesh read_binary(const std::string& path, const std::string& bytes) {
  std::uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 80, 4);
  const std::size_t expected = 84 + 50 * std::size_t(count);
  require(bytes.size() == expected,
          "binary STL header says " + std::to_string(count) + " triangles (" + std::to_string(expected) +
              " bytes) but the file has " + std::to_string(bytes.size()) + " bytes" +
              (bytes.size() < expected ? ": truncated" : ""),
          path, "export the surface again (binary or ASCII STL)");
  Welder w(path);
  for (std::size_t t = 0; t < count; ++t) {
    const char* facet = bytes.data() + 84 + 50 * t + 12;  // after the normal (ignored: from the winding)
    std::array<std::array<double, 3>, 3> corners;
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) {
        float x;
        std::memcpy(&x, facet + 12 * k + 4 * a, 4);
        corners[std::size_t(k)][std::size_t(a)] = x;
      }
    w.add_triangle(corners, t);
  }
  return std::move(w.mesh);
}

TriangleMesh read_ascii(const std::string& path, const std::string& text) {
  std::istringstream in(text);
  std::string word;
  in >> word;  // "solid"
  std::getline(in, word);  // its name
  Welder w(path);
  std::size_t facet = 0;
  const auto expect = [&](const char* token) {
    require(bool(in >> word) && word == token,
            "ASCII STL: expected '" + std::string(token) + "' in facet " + std::to_string(facet + 1) +
                (in ? ", found '" + word + "'" : ", found the end of the file (truncated)"),
            path, "export the surface again");
  };
  while (in >> word) {
    if (word == "endsolid") return std::move(w.mesh);
    require(word == "facet", "ASCII STL: expected 'facet' or 'endsolid', found '" + word + "'", path);
    expect("normal");
    for (int a = 0; a < 3; ++a) in >> word;
    expect("outer");
    expect("loop");
    std::array<std::array<double, 3>, 3> corners;
    for (int k = 0; k < 3; ++k) {
      expect("vertex");
      for (int a = 0; a < 3; ++a) {
        require(bool(in >> word), "ASCII STL: facet " + std::to_string(facet + 1) + " ends early (truncated)", path);
        std::size_t used = 0;
        double x = NAN;
        try {
          x = std::stod(word, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        require(used == word.size() && used > 0,
                "ASCII STL: facet " + std::to_string(facet + 1) + " has '" + word + "' where a coordinate belongs", path);
        corners[std::size_t(k)][std::size_t(a)] = x;
      }
    }
    expect("endloop");
    expect("endfacet");
    w.add_triangle(corners, facet++);
  }
  throw Error("ASCII STL ends without 'endsolid' after " + std::to_string(facet) + " facets: truncated", path,
              "export the surface again");
}

}  // namespace

TriangleMesh read_stl(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  require(bool(in), "cannot open the surface mesh", path, "check the path");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // ASCII starts with "solid"; so do some binary files, whose size then matches their count
  bool ascii = bytes.compare(0, 5, "solid") == 0;
  if (ascii && bytes.size() >= 84) {
    std::uint32_t count = 0;
    std::memcpy(&count, bytes.data() + 80, 4);
    if (bytes.size() == 84 + 50 * std::size_t(count)) ascii = false;
  }
  if (!ascii) require(bytes.size() >= 84, "too short for a binary STL (" + std::to_string(bytes.size()) + " bytes)", path,
                      "export the surface again (binary or ASCII STL)");
  TriangleMesh mesh = ascii ? read_ascii(path, bytes) : read_binary(path, bytes);
  require(!mesh.triangles.empty(), "the STL holds no triangle", path, "give a closed surface of the observed region");
  return mesh;
}

}  // namespace vb
