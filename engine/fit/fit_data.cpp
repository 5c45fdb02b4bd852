#include "engine/fit/fit_data.hpp"


namespace vb {

ResidualRows DisplacementData::rows(const std::vector<double>& change_m) const {
  const std::size_t observed = obs_.observed_elements();
  ResidualRows r;
  r.value_m.resize(Eigen::Index(3 * observed));
  r.weight_per_m2.resize(Eigen::Index(3 * observed));
  Eigen::Index row = 0;
  for (std::size_t e = 0; e < obs_.weight_per_m2.size(); ++e) {
    const double w = obs_.weight_per_m2[e];
    if (w <= 0) continue;
    for (int a = 0; a < 3; ++a, ++row) {
      r.value_m[row] = change_m[3 * e + a] - obs_.displacement_m[3 * e + a];
      r.weight_per_m2[row] = w;
    }
  }
  return r;
}

}  // namespace vb
