#pragma once
// Test helpers for surface meshes: lattices from voxel predicates, topology (closed, manifold,
// oriented, Euler characteristic per component) and a triangle–triangle intersection search.
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cstdint>
#include <numeric>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include "engine/lattice/lattice.hpp"
#include "engine/surface/surface_mesh.hpp"

namespace vb::test {

/// A one-tissue lattice of `dims` voxels of spacing h (m): voxel (i, j, k) is occupied where
/// inside(i, j, k). The origin is away from 0 so that world positions exercise rounding.
template <class Inside>
Lattice lattice_where(std::array<int, 3> dims, Inside inside, double h = 0.002) {
  LabelVolume v;
  v.dims = dims;
  v.spacing_m = h;
  v.origin_m = Eigen::Vector3d(0.11, -0.23, 0.057);
  v.tissue_names = {"soft"};
  v.labels.assign(std::size_t(dims[0]) * dims[1] * dims[2], 0);
  for (int k = 0; k < dims[2]; ++k)
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < dims[0]; ++i) v.labels[v.linear_index(i, j, k)] = inside(i, j, k) ? 1 : 0;
  return build_lattice(v);
}

struct MeshTopology {
  std::size_t vertices = 0, edges = 0, faces = 0, components = 0;
  long euler = 0;
  long genus = 0;                  ///< Σ over components of (2 − χ_c)/2
  std::vector<std::string> problems;  ///< empty when closed, 2-manifold and consistently oriented
  std::string describe() const {
    std::ostringstream s;
    s << "V=" << vertices << " E=" << edges << " F=" << faces << " chi=" << euler << " components="
      << components << " genus=" << genus;
    for (std::size_t i = 0; i < std::min<std::size_t>(problems.size(), 5); ++i) s << "\n  " << problems[i];
    if (problems.size() > 5) s << "\n  ... " << problems.size() - 5 << " more";
    return s.str();
  }
};

/// Checks by vertex ids: 3 distinct vertices per triangle; every directed edge in exactly one
/// triangle and its reverse in another (closed, each edge shared by exactly two triangles,
/// consistent orientation); the triangles around each vertex form one closed fan; every vertex
/// used. Counts V, E, F and components, and the genus from χ per component.
inline MeshTopology check_topology(const SurfaceMesh& mesh) {
  MeshTopology t;
  const std::size_t nv = mesh.vertex_count();
  auto key = [](std::uint64_t a, std::uint64_t b) { return a << 32 | b; };
  std::unordered_map<std::uint64_t, int> directed;
  std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> link(nv);
  std::vector<std::uint32_t> parent(nv);
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (const auto& tri : mesh.triangles) {
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] || std::max({tri[0], tri[1], tri[2]}) >= nv) {
      t.problems.push_back("bad triangle");
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = tri[k], b = tri[(k + 1) % 3], c = tri[(k + 2) % 3];
      if (++directed[key(a, b)] == 2)
        t.problems.push_back("directed edge " + std::to_string(a) + "->" + std::to_string(b) + " twice");
      link[a].push_back({b, c});
      parent[find(a)] = find(b);
    }
  }
  for (const auto& [k, count] : directed) {
    const std::uint64_t a = k >> 32, b = k & 0xffffffffu;
    if (!directed.count(key(b, a)))
      t.problems.push_back("edge " + std::to_string(a) + "-" + std::to_string(b) + " has one triangle");
    if (a < b || !directed.count(key(b, a))) ++t.edges;
  }
  for (std::uint32_t v = 0; v < nv; ++v) {
    const auto& l = link[v];
    if (l.empty()) {
      t.problems.push_back("vertex " + std::to_string(v) + " in no triangle");
      continue;
    }
    // Walk next(b) = c around v; one cycle must visit every triangle of v.
    std::unordered_map<std::uint32_t, std::uint32_t> next;
    for (const auto& [b, c] : l) next[b] = c;
    std::uint32_t x = l[0].first;
    std::size_t steps = 0;
    do {
      auto it = next.find(x);
      if (it == next.end()) break;
      x = it->second;
      ++steps;
    } while (x != l[0].first && steps <= l.size());
    if (steps != l.size() || x != l[0].first)
      t.problems.push_back("vertex " + std::to_string(v) + " (element " + std::to_string(mesh.element_of_vertex[v]) +
                           ") is not one closed fan");
  }
  t.vertices = nv;
  t.faces = mesh.triangles.size();
  t.euler = long(t.vertices) - long(t.edges) + long(t.faces);
  // χ per component: V_c − E_c + F_c, with E_c = half-edges / 2 (each edge has two).
  std::unordered_map<std::uint32_t, long> v_c, half_c, f_c;
  for (std::uint32_t v = 0; v < nv; ++v) ++v_c[find(v)];
  for (const auto& tri : mesh.triangles) {
    ++f_c[find(tri[0])];
    half_c[find(tri[0])] += 3;
  }
  t.components = v_c.size();
  for (const auto& [root, nvc] : v_c) {
    const long chi_c = nvc - half_c[root] / 2 + f_c[root];
    if (chi_c % 2 != 0 || chi_c > 2) t.problems.push_back("component with chi " + std::to_string(chi_c));
    t.genus += (2 - chi_c) / 2;
  }
  return t;
}

/// Lattice-frame rest coordinates of an element's voxel (integers, exact in double).
inline Eigen::Vector3d voxel_coordinates(const Lattice& lattice, std::uint32_t e) {
  const auto ijk = lattice.voxel_ijk(e);
  return Eigen::Vector3d(ijk[0], ijk[1], ijk[2]);
}

/// Separating-axis test for two closed triangles (touching counts as intersecting). Exact for
/// small integer coordinates.
inline bool triangles_intersect(const std::array<Eigen::Vector3d, 3>& A, const std::array<Eigen::Vector3d, 3>& B) {
  auto separated = [&](const Eigen::Vector3d& axis) {
    if (axis.squaredNorm() == 0) return false;
    double a0 = A[0].dot(axis), a1 = a0, b0 = B[0].dot(axis), b1 = b0;
    for (int k = 1; k < 3; ++k) {
      a0 = std::min(a0, A[k].dot(axis)), a1 = std::max(a1, A[k].dot(axis));
      b0 = std::min(b0, B[k].dot(axis)), b1 = std::max(b1, B[k].dot(axis));
    }
    return a1 < b0 || b1 < a0;
  };
  const std::array<Eigen::Vector3d, 3> ea{A[1] - A[0], A[2] - A[1], A[0] - A[2]};
  const std::array<Eigen::Vector3d, 3> eb{B[1] - B[0], B[2] - B[1], B[0] - B[2]};
  const Eigen::Vector3d na = ea[0].cross(ea[1]), nb = eb[0].cross(eb[1]);
  if (separated(na) || separated(nb)) return false;
  for (const auto& u : ea)
    for (const auto& w : eb)
      if (separated(u.cross(w))) return false;
  if (na.cross(nb).squaredNorm() == 0)  // coplanar (parallel planes apart were separated by na)
    for (int k = 0; k < 3; ++k)
      if (separated(na.cross(ea[k])) || separated(nb.cross(eb[k]))) return false;
  return true;
}

/// Pairs of triangles that intersect at rest (lattice frame), skipping pairs that share a vertex
/// position (an element). Bucketed by the lowest corner of each triangle's box: triangles span at
/// most one lattice step per axis, so only neighbouring buckets can meet.
inline std::size_t count_rest_intersections(const Lattice& lattice, const SurfaceMesh& mesh) {
  auto bucket_key = [](const Eigen::Vector3d& p) {
    return (std::uint64_t(std::int64_t(p.x()) + 2) << 42) | (std::uint64_t(std::int64_t(p.y()) + 2) << 21) |
           std::uint64_t(std::int64_t(p.z()) + 2);
  };
  std::vector<std::array<Eigen::Vector3d, 3>> tri(mesh.triangles.size());
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> buckets;
  for (std::size_t t = 0; t < tri.size(); ++t) {
    for (int k = 0; k < 3; ++k) tri[t][k] = voxel_coordinates(lattice, mesh.element_of_vertex[mesh.triangles[t][k]]);
    buckets[bucket_key(tri[t][0].cwiseMin(tri[t][1]).cwiseMin(tri[t][2]))].push_back(t);
  }
  std::size_t hits = 0;
  for (std::size_t t = 0; t < tri.size(); ++t) {
    const Eigen::Vector3d lo = tri[t][0].cwiseMin(tri[t][1]).cwiseMin(tri[t][2]);
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const auto it = buckets.find(bucket_key(lo + Eigen::Vector3d(dx, dy, dz)));
          if (it == buckets.end()) continue;
          for (const std::size_t u : it->second) {
            if (u <= t) continue;
            bool shared = false;
            for (int a = 0; a < 3; ++a)
              for (int b = 0; b < 3; ++b)
                shared = shared || mesh.element_of_vertex[mesh.triangles[t][a]] == mesh.element_of_vertex[mesh.triangles[u][b]];
            if (!shared && triangles_intersect(tri[t], tri[u])) ++hits;
          }
        }
  }
  return hits;
}

}  // namespace vb::test
