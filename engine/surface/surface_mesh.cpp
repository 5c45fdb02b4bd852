#include "engine/surface/surface_mesh.hpp"

#include <Eigen/Dense>

#include "engine/error.hpp"
#include "engine/surface/surface_elements.hpp"

namespace vb {
namespace {

// Local geometry around one element v (docs/SURFACE.md, "Fans"):
// - octant o (0..7): the dual cell on the + side of axis a where bit a of o is set;
// - local square s = 4a + q (0..11): the unit square of the lattice plane ⊥ axis a through v,
//   on side (q & 1) of axis b = (a+1) % 3 and side (q >> 1) of axis c = (a+2) % 3 (1: + side).
//   It lies between the two octants that differ in bit a; it is a boundary face when exactly
//   one of them is complete;
// - edge E = 2b + σ (0..5): the lattice edge from v along axis b, on side σ. Four squares meet
//   there, each square touches two edges at v.

constexpr std::uint8_t kNoFan = 0xFF;

int square_index(int a, const std::array<int, 3>& side) {
  return 4 * a + side[(a + 1) % 3] + 2 * side[(a + 2) % 3];
}

int octant_index(const std::array<int, 3>& side) { return side[0] | side[1] << 1 | side[2] << 2; }

struct LocalTopology {
  std::array<std::array<int, 2>, 12> octants_of_square{};  ///< [a− side, a+ side]
  std::array<std::array<int, 2>, 12> edges_of_square{};
  /// around edge E, the octants in cyclic order and the square between ring octant i and i+1
  std::array<std::array<int, 4>, 6> ring_octants{}, ring_squares{};
};

const LocalTopology& local_topology() {
  static const LocalTopology t = [] {
    LocalTopology t;
    for (int s = 0; s < 12; ++s) {
      const int a = s / 4, q = s % 4, b = (a + 1) % 3, c = (a + 2) % 3;
      std::array<int, 3> side{};
      side[b] = q & 1;
      side[c] = q >> 1;
      for (int k = 0; k < 2; ++k) {
        side[a] = k;
        t.octants_of_square[s][k] = octant_index(side);
      }
      t.edges_of_square[s] = {2 * b + (q & 1), 2 * c + (q >> 1)};
    }
    for (int E = 0; E < 6; ++E) {
      const int b = E / 2, p1 = (b + 1) % 3, p2 = (b + 2) % 3;
      const int ring[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};  // (p1, p2) sides, cyclic
      for (int i = 0; i < 4; ++i) {
        std::array<int, 3> side{};
        side[b] = E % 2;
        side[p1] = ring[i][0];
        side[p2] = ring[i][1];
        t.ring_octants[E][i] = octant_index(side);
        // The next octant differs in p1 (i even) or p2 (i odd); the square between them is
        // ⊥ that axis, with the other sides shared.
        const int* next = ring[(i + 1) % 4];
        const int across = ring[i][0] != next[0] ? p1 : p2;
        t.ring_squares[E][i] = square_index(across, side);
      }
    }
    return t;
  }();
  return t;
}

bool octant_complete(std::uint8_t octants, int o) { return (octants >> o & 1u) != 0; }

bool is_boundary_square(std::uint8_t octants, int s) {
  const auto& oc = local_topology().octants_of_square[s];
  return octant_complete(octants, oc[0]) != octant_complete(octants, oc[1]);
}

/// The 4 octants around edge E alternate complete / incomplete: two complete cells meet only
/// along this edge (4 boundary faces meet there).
bool is_pinch_edge(std::uint8_t octants, int E) {
  const auto& ring = local_topology().ring_octants[E];
  bool alternating = true;
  for (int i = 0; i < 4; ++i)
    alternating = alternating && octant_complete(octants, ring[i]) != octant_complete(octants, ring[(i + 1) % 4]);
  return alternating;
}

struct Fans {
  std::array<std::uint8_t, 12> fan_of_square;  ///< kNoFan where the square is not a boundary face
  std::uint8_t count = 0;
};

/// Groups the boundary faces around an element into fans. At each edge, the faces pair across
/// each run of complete cells around the edge (the cells are joined through faces only), or,
/// where bit E of `empty_paired` is set, across each run of incomplete cells. With 2 faces at
/// an edge both rules pair them; they differ only at a pinch edge (4 faces).
Fans group_fans(std::uint8_t octants, unsigned empty_paired) {
  const LocalTopology& t = local_topology();
  std::array<std::array<int, 2>, 12> partner{};
  for (int E = 0; E < 6; ++E) {
    const bool paired_kind = !(empty_paired >> E & 1u);  // complete (true) or incomplete runs
    bool in_run[4];
    for (int i = 0; i < 4; ++i) in_run[i] = octant_complete(octants, t.ring_octants[E][i]) == paired_kind;
    for (int i = 0; i < 4; ++i) {
      if (!in_run[i] || in_run[(i + 3) % 4]) continue;  // not the start of a run
      int j = i;
      while (in_run[(j + 1) % 4]) ++j;
      const int first = t.ring_squares[E][(i + 3) % 4], last = t.ring_squares[E][j % 4];
      partner[first][t.edges_of_square[first][0] == E ? 0 : 1] = last;
      partner[last][t.edges_of_square[last][0] == E ? 0 : 1] = first;
    }
  }
  Fans fans;
  fans.fan_of_square.fill(kNoFan);
  for (int start = 0; start < 12; ++start) {
    if (!is_boundary_square(octants, start) || fans.fan_of_square[start] != kNoFan) continue;
    // Walk the cycle: leave each face by the edge it was not entered through.
    int s = start, out = 0;
    do {
      fans.fan_of_square[s] = fans.count;
      const int edge = t.edges_of_square[s][out];
      const int next = partner[s][out];
      out = t.edges_of_square[next][0] == edge ? 1 : 0;
      s = next;
    } while (s != start);
    ++fans.count;
  }
  return fans;
}

}  // namespace

SurfaceMesh build_surface(const Lattice& lattice) {
  const LocalTopology& topo = local_topology();
  const std::size_t n = lattice.element_count();
  const std::vector<std::uint8_t> octants = complete_octants_of_elements(lattice);

  SurfaceMesh mesh;
  std::vector<std::uint32_t> surface;       // surface elements, ascending
  std::vector<std::int32_t> slot(n, -1);    // element → index in `surface`
  for (std::size_t e = 0; e < n; ++e) {
    mesh.complete_cell_count += octant_complete(octants[e], 7);  // the cell with e at its min corner
    if (octants[e] == 0) ++mesh.outside_body_count;
    if (octants[e] == 0 || octants[e] == 0xFF) continue;
    slot[e] = static_cast<std::int32_t>(surface.size());
    surface.push_back(static_cast<std::uint32_t>(e));
  }
  mesh.surface_element_count = surface.size();

  const std::array<std::size_t, 3> stride{1, std::size_t(lattice.dims[0]),
                                          std::size_t(lattice.dims[0]) * std::size_t(lattice.dims[1])};
  // Element one step along axis b (sign ±1), -1 outside the grid or where empty.
  auto step = [&](std::uint32_t e, int b, int sign) -> std::int32_t {
    const auto ijk = lattice.voxel_ijk(e);
    const int to = ijk[b] + sign;
    if (to < 0 || to >= lattice.dims[b]) return -1;
    const std::size_t v = lattice.voxel_of_element[e];
    return lattice.element_of_voxel[sign > 0 ? v + stride[b] : v - stride[b]];
  };

  // empty_paired[slot] bit b: the edge from the element along +b pairs its faces around the
  // incomplete cells. Edges along −b are stored at the element on that side.
  std::vector<std::uint8_t> empty_paired(surface.size(), 0);
  auto edge_flags = [&](std::uint32_t e) {
    unsigned flags = 0;
    for (int b = 0; b < 3; ++b) {
      flags |= unsigned(empty_paired[std::size_t(slot[e])] >> b & 1u) << (2 * b + 1);
      const std::int32_t below = step(e, b, -1);
      if (below >= 0 && slot[std::size_t(below)] >= 0)
        flags |= unsigned(empty_paired[std::size_t(slot[std::size_t(below)])] >> b & 1u) << (2 * b);
    }
    return flags;
  };

  std::vector<Fans> fans(surface.size());
  for (std::size_t i = 0; i < surface.size(); ++i) fans[i] = group_fans(octants[surface[i]], 0);

  // At a pinch edge v–w the two pairs of faces give two mesh edges. If each pair lies in the
  // same fan as the other at both v and w, the two edges would join the same two vertices: then
  // pair the faces around the incomplete cells instead, which splits the fan at both ends (a
  // re-paired crossing of one closed fan splits it). Splitting never merges fans, so one pass
  // in element order settles every edge and the result is deterministic.
  for (std::size_t i = 0; i < surface.size(); ++i) {
    const std::uint32_t v = surface[i];
    for (int b = 0; b < 3; ++b) {
      if (!is_pinch_edge(octants[v], 2 * b + 1)) continue;
      const std::int32_t w = step(v, b, +1);
      require(w >= 0 && slot[std::size_t(w)] >= 0, "surface: pinch edge without a surface element at its end");
      const std::size_t j = std::size_t(slot[std::size_t(w)]);
      const auto& at_v = topo.ring_squares[2 * b + 1];  // the same faces, seen from v and from w
      const auto& at_w = topo.ring_squares[2 * b];
      // ring squares 0 and 2 always belong to different pairs
      const bool same_at_v = fans[i].fan_of_square[at_v[0]] == fans[i].fan_of_square[at_v[2]];
      const bool same_at_w = fans[j].fan_of_square[at_w[0]] == fans[j].fan_of_square[at_w[2]];
      if (!same_at_v || !same_at_w) continue;
      empty_paired[i] |= std::uint8_t(1u << b);
      ++mesh.empty_paired_edge_count;
      fans[i] = group_fans(octants[v], edge_flags(v));
      fans[j] = group_fans(octants[std::size_t(w)], edge_flags(std::uint32_t(w)));
    }
  }

  // Vertices: one per fan, in element order.
  std::vector<std::uint32_t> first_vertex(surface.size());
  const Eigen::Matrix3d& R = lattice.rotation;
  for (std::size_t i = 0; i < surface.size(); ++i) {
    first_vertex[i] = static_cast<std::uint32_t>(mesh.element_of_vertex.size());
    mesh.split_element_count += fans[i].count > 1;
    std::array<Eigen::Vector3d, 12> normal_sum;
    normal_sum.fill(Eigen::Vector3d::Zero());
    for (int s = 0; s < 12; ++s) {
      const std::uint8_t f = fans[i].fan_of_square[s];
      if (f == kNoFan) continue;
      const bool solid_below = octant_complete(octants[surface[i]], topo.octants_of_square[s][0]);
      normal_sum[f][s / 4] += solid_below ? 1.0 : -1.0;
    }
    for (int f = 0; f < fans[i].count; ++f) {
      mesh.element_of_vertex.push_back(surface[i]);
      mesh.normal_of_vertex.push_back((R * normal_sum[f]).normalized());
    }
  }

  // Boundary faces, each emitted once from its corner with the lowest coordinates (where it is
  // local square q = 3 of plane a), as two triangles sharing the diagonal from that corner.
  const bool mirrored = R.determinant() < 0;  // a left-handed world frame reverses the winding
  mesh.triangles.reserve(4 * surface.size());
  auto vertex = [&](std::size_t voxel, int s) {
    const std::size_t k = std::size_t(slot[std::size_t(lattice.element_of_voxel[voxel])]);
    return first_vertex[k] + fans[k].fan_of_square[s];
  };
  auto add = [&](std::uint32_t x0, std::uint32_t x1, std::uint32_t x2) {
    mesh.triangles.push_back(mirrored ? std::array{x0, x2, x1} : std::array{x0, x1, x2});
  };
  for (std::size_t i = 0; i < surface.size(); ++i) {
    const std::uint32_t e = surface[i];
    const std::size_t v = lattice.voxel_of_element[e];
    for (int a = 0; a < 3; ++a) {
      if (!is_boundary_square(octants[e], 4 * a + 3)) continue;
      const std::size_t sb = stride[(a + 1) % 3], sc = stride[(a + 2) % 3];
      // corners (b, c) = (0,0), (1,0), (1,1), (0,1); each is local square q = 3, 2, 0, 1 there
      const std::uint32_t p00 = first_vertex[i] + fans[i].fan_of_square[4 * a + 3];
      const std::uint32_t p10 = vertex(v + sb, 4 * a + 2);
      const std::uint32_t p11 = vertex(v + sb + sc, 4 * a + 0);
      const std::uint32_t p01 = vertex(v + sc, 4 * a + 1);
      const bool outward_plus = octant_complete(octants[e], topo.octants_of_square[4 * a + 3][0]);
      if (outward_plus) {  // counter-clockwise seen from +a: e_b × e_c = e_a
        add(p00, p10, p11);
        add(p00, p11, p01);
      } else {
        add(p00, p11, p10);
        add(p00, p01, p11);
      }
    }
  }
  return mesh;
}

std::vector<double> element_positions_m(const Lattice& lattice, std::span<const double> displacement_m) {
  const std::size_t n = lattice.element_count();
  require(displacement_m.empty() || displacement_m.size() == 3 * n,
          "displacement array does not match the element count (n × 3 expected)");
  std::vector<double> x(3 * n);
  for (std::size_t e = 0; e < n; ++e) {
    const Eigen::Vector3d p = lattice.rest_position(e);
    for (int c = 0; c < 3; ++c) x[3 * e + c] = p[c] + (displacement_m.empty() ? 0.0 : displacement_m[3 * e + c]);
  }
  return x;
}

}  // namespace vb
