#include "engine/fit/mesh_distance.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>

#include "engine/error.hpp"

namespace vb {
namespace {

/// feature of a triangle: vertex k (0–2), edge k from vertex k to k+1 (3–5), the face (6)
struct Closest {
  Eigen::Vector3d point;
  int feature;
};

/// The nearest point of triangle abc to p (Ericson, Real-Time Collision Detection §5.1.5).
Closest closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                            const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {a, 0};
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {b, 1};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return {a + d1 / (d1 - d3) * ab, 3};
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {c, 2};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return {a + d2 / (d2 - d6) * ac, 5};
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) return {b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b), 4};
  const double denom = 1 / (va + vb + vc);
  return {a + ab * (vb * denom) + ac * (vc * denom), 6};
}

double box_distance2(const Eigen::Vector3d& p, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  return (lo - p).cwiseMax(p - hi).cwiseMax(0.0).squaredNorm();
}

}  // namespace

MeshSignedDistance::MeshSignedDistance(TriangleMesh mesh, const std::string& what) : mesh_(std::move(mesh)) {
  const std::size_t nv = mesh_.vertices_m.size();
  for (std::size_t v = 0; v < nv; ++v)
    require(mesh_.vertices_m[v].allFinite(), "vertex " + std::to_string(v) + " is not a finite number", what,
            "export the surface again");
  auto& tris = mesh_.triangles;
  for (const auto& t : tris)
    for (const std::uint32_t v : t) require(v < nv, "a triangle refers to a vertex beyond the mesh", what);
  // triangles with two equal corners (slivers that welding collapsed) have no area and no edges
  std::erase_if(tris, [](const auto& t) { return t[0] == t[1] || t[1] == t[2] || t[2] == t[0]; });
  require(!tris.empty(), "the surface mesh has no triangle", what, "give a closed surface of the observed region");

  // closed and consistently oriented: each directed edge a→b is matched by as many b→a
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> edges;  // (lo, hi) → 2·tri + (a < b)
  for (std::size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = tris[t][k], b = tris[t][(k + 1) % 3];
      edges[{std::min(a, b), std::max(a, b)}].push_back(std::uint32_t(2 * t + (a < b)));
    }
  for (const auto& [e, uses] : edges) {
    const std::size_t forward = std::size_t(std::count_if(uses.begin(), uses.end(), [](std::uint32_t u) { return u & 1; }));
    require(2 * forward == uses.size(),
            "the surface mesh is not closed: the edge between vertices at (" +
                std::to_string(1e3 * mesh_.vertices_m[e.first].x()) + ", " + std::to_string(1e3 * mesh_.vertices_m[e.first].y()) +
                ", " + std::to_string(1e3 * mesh_.vertices_m[e.first].z()) + ") mm and (" +
                std::to_string(1e3 * mesh_.vertices_m[e.second].x()) + ", " + std::to_string(1e3 * mesh_.vertices_m[e.second].y()) +
                ", " + std::to_string(1e3 * mesh_.vertices_m[e.second].z()) + ") mm has " + std::to_string(uses.size()) +
                " triangle(s), " + std::to_string(forward) + " of them one way round",
            what, "give a closed (watertight), consistently oriented surface; fill holes before exporting");
  }
  for (const auto& t : tris) {
    const Eigen::Vector3d& a = mesh_.vertices_m[t[0]];
    volume_m3_ += a.dot(mesh_.vertices_m[t[1]].cross(mesh_.vertices_m[t[2]])) / 6;
  }
  require(volume_m3_ != 0, "the surface mesh encloses no volume", what);
  if (volume_m3_ < 0) {  // inward-facing: turn every triangle (the mesh is consistent, so all of them)
    for (auto& t : tris) std::swap(t[1], t[2]);
    volume_m3_ = -volume_m3_;
  }

  // pseudo-normals
  const std::size_t nt = tris.size();
  face_normal_.resize(nt);
  for (std::size_t t = 0; t < nt; ++t) {
    const Eigen::Vector3d& a = mesh_.vertices_m[tris[t][0]];
    const Eigen::Vector3d n = (mesh_.vertices_m[tris[t][1]] - a).cross(mesh_.vertices_m[tris[t][2]] - a);
    face_normal_[t] = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::Zero();
  }
  edge_normal_.assign(nt, {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()});
  edge_manifold_.assign(nt, {true, true, true});
  vertex_normal_.assign(nv, Eigen::Vector3d::Zero());
  vertex_manifold_.assign(nv, true);
  for (const auto& [e, uses] : edges) {
    const bool manifold = uses.size() == 2;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const std::uint32_t u : uses) sum += face_normal_[u / 2];
    for (const std::uint32_t u : uses) {
      const std::size_t t = u / 2;
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t a = tris[t][k], b = tris[t][(k + 1) % 3];
        if (std::min(a, b) != e.first || std::max(a, b) != e.second) continue;
        edge_normal_[t][k] = sum;
        edge_manifold_[t][k] = manifold;
      }
    }
    if (!manifold) vertex_manifold_[e.first] = vertex_manifold_[e.second] = false;
  }
  // vertex normals (angle-weighted) and fans: a vertex whose triangles form more than one fan
  // (joined through its edges) is a point where parts touch
  std::vector<std::vector<std::uint32_t>> around(nv);
  for (std::size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = tris[t][k];
      const Eigen::Vector3d e1 = mesh_.vertices_m[tris[t][(k + 1) % 3]] - mesh_.vertices_m[v];
      const Eigen::Vector3d e2 = mesh_.vertices_m[tris[t][(k + 2) % 3]] - mesh_.vertices_m[v];
      const double n1 = e1.norm(), n2 = e2.norm();
      if (n1 > 0 && n2 > 0) vertex_normal_[v] += std::acos(std::clamp(e1.dot(e2) / (n1 * n2), -1.0, 1.0)) * face_normal_[t];
      around[v].push_back(std::uint32_t(t));
    }
  for (std::size_t v = 0; v < nv; ++v) {
    if (!vertex_manifold_[v] || around[v].empty()) continue;
    const auto& ts = around[v];
    std::vector<std::size_t> parent(ts.size());
    std::iota(parent.begin(), parent.end(), 0);
    const auto root = [&](std::size_t i) {
      while (parent[i] != i) i = parent[i] = parent[parent[i]];
      return i;
    };
    for (std::size_t i = 0; i < ts.size(); ++i)
      for (std::size_t j = i + 1; j < ts.size(); ++j) {
        int shared = 0;  // corners the two triangles share (v among them)
        for (const std::uint32_t a : tris[ts[i]])
          for (const std::uint32_t b : tris[ts[j]]) shared += a == b;
        if (shared >= 2) parent[root(i)] = root(j);
      }
    std::size_t fans = 0;
    for (std::size_t i = 0; i < ts.size(); ++i) fans += root(i) == i;
    vertex_manifold_[v] = fans == 1;
  }

  order_.resize(nt);
  std::iota(order_.begin(), order_.end(), 0);
  nodes_.reserve(2 * nt / 4 + 2);
  build(0, std::uint32_t(nt));
}

std::uint32_t MeshSignedDistance::build(std::uint32_t first, std::uint32_t count) {
  const std::uint32_t id = std::uint32_t(nodes_.size());
  nodes_.push_back({});
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  Eigen::Vector3d clo = lo, chi = hi;  // centroid bounds
  for (std::uint32_t i = first; i < first + count; ++i) {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const std::uint32_t v : mesh_.triangles[order_[i]]) {
      lo = lo.cwiseMin(mesh_.vertices_m[v]);
      hi = hi.cwiseMax(mesh_.vertices_m[v]);
      centroid += mesh_.vertices_m[v] / 3;
    }
    clo = clo.cwiseMin(centroid);
    chi = chi.cwiseMax(centroid);
  }
  Node node{lo, hi, first, count, 0, 0};
  if (count > 4) {
    int axis;
    (chi - clo).maxCoeff(&axis);
    const std::uint32_t half = count / 2;
    const auto centre = [&](std::uint32_t t) {
      const auto& tri = mesh_.triangles[t];
      return mesh_.vertices_m[tri[0]][axis] + mesh_.vertices_m[tri[1]][axis] + mesh_.vertices_m[tri[2]][axis];
    };
    std::nth_element(order_.begin() + first, order_.begin() + first + half, order_.begin() + first + count,
                     [&](std::uint32_t a, std::uint32_t b) { return centre(a) < centre(b); });
    node.count = 0;
    node.left = build(first, half);
    node.right = build(first + half, count - half);
  }
  nodes_[id] = node;
  return id;
}

double MeshSignedDistance::winding_number(const Eigen::Vector3d& p) const {
  double sum = 0;  // solid angles (Van Oosterom & Strackee 1983)
  for (const auto& t : mesh_.triangles) {
    const Eigen::Vector3d a = mesh_.vertices_m[t[0]] - p, b = mesh_.vertices_m[t[1]] - p, c = mesh_.vertices_m[t[2]] - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    sum += 2 * std::atan2(a.dot(b.cross(c)), la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb);
  }
  return sum / (4 * std::numbers::pi);
}

double MeshSignedDistance::at(const Eigen::Vector3d& p) const {
  double best = std::numeric_limits<double>::infinity();
  std::uint32_t best_tri = 0;
  Closest best_point{p, 6};
  std::uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (box_distance2(p, n.lo, n.hi) >= best) continue;
    if (n.count > 0) {
      for (std::uint32_t i = n.first; i < n.first + n.count; ++i) {
        const auto& t = mesh_.triangles[order_[i]];
        const Closest c = closest_on_triangle(p, mesh_.vertices_m[t[0]], mesh_.vertices_m[t[1]], mesh_.vertices_m[t[2]]);
        const double d2 = (p - c.point).squaredNorm();
        if (d2 < best) {
          best = d2;
          best_tri = order_[i];
          best_point = c;
        }
      }
      continue;
    }
    const double dl = box_distance2(p, nodes_[n.left].lo, nodes_[n.left].hi);
    const double dr = box_distance2(p, nodes_[n.right].lo, nodes_[n.right].hi);
    // the nearer child is popped first
    stack[top++] = dl < dr ? n.right : n.left;
    stack[top++] = dl < dr ? n.left : n.right;
  }
  const double d = std::sqrt(best);
  if (d == 0) return 0;
  const auto& t = mesh_.triangles[best_tri];
  Eigen::Vector3d normal;
  bool defined = true;
  if (best_point.feature == 6) {
    normal = face_normal_[best_tri];
  } else if (best_point.feature >= 3) {
    normal = edge_normal_[best_tri][best_point.feature - 3];
    defined = edge_manifold_[best_tri][best_point.feature - 3];
  } else {
    normal = vertex_normal_[t[std::size_t(best_point.feature)]];
    defined = vertex_manifold_[t[std::size_t(best_point.feature)]];
  }
  const double side = normal.dot(p - best_point.point);
  if (!defined || side == 0) return winding_number(p) > 0.5 ? -d : d;
  return side < 0 ? -d : d;
}

}  // namespace vb
