#include "engine/material/linear_spring.hpp"

#include <cmath>

#include "engine/lattice/lattice.hpp"

namespace vb::linear_spring {
namespace {

int order_of(int d) {
  const auto& o = neighbour_offsets()[d];
  return o[0] * o[0] + o[1] * o[1] + o[2] * o[2];
}

}  // namespace

double kappa(int d) {
  switch (order_of(d)) {
    case 1: return kappa_face;
    case 2: return kappa_edge;
    default: return kappa_corner;
  }
}

double rest_length_factor(int d) { return std::sqrt(double(order_of(d))); }

}  // namespace vb::linear_spring
