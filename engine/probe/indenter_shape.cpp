#include "engine/probe/indenter_shape.hpp"

#include <algorithm>
#include <cmath>

namespace vb {

double indenter_signed_distance(const IndenterSpec& ind, const Vec3& p, const Vec3& x) {
  const Vec3 d = x - p;
  const Vec3& a = ind.normal;
  switch (ind.kind) {
    case IndenterSpec::Kind::Plate:
      return d.dot(a);
    case IndenterSpec::Kind::Cylinder: {
      const double s = d.dot(a), out = (d - s * a).norm() - ind.radius_m;
      if (s > 0 && out > 0) return std::hypot(s, out);
      return (s > 0 || (out <= 0 && s >= out)) ? s : out;
    }
    case IndenterSpec::Kind::Capsule:
      return (x - (p + std::clamp(d.dot(a), 0.0, ind.length_m) * a)).norm() - ind.radius_m;
    case IndenterSpec::Kind::Sphere:
      break;
  }
  return d.norm() - ind.radius_m;
}

}  // namespace vb
