#include "engine/loads/posture.hpp"

#include <array>

#include "engine/error.hpp"

namespace vb {
namespace {

struct Posture {
  const char* name;
  std::array<double, 3> direction;  ///< unit direction of gravity in LPS
};

// Lying on the back pulls tissue towards the back (+Posterior); lying on the left side pulls it
// towards the patient's left (+Left); standing pulls it towards the feet (-Superior).
constexpr std::array<Posture, 5> kPostures{{
    {"supine", {0, 1, 0}},
    {"prone", {0, -1, 0}},
    {"upright", {0, 0, -1}},
    {"left_lateral", {1, 0, 0}},
    {"right_lateral", {-1, 0, 0}},
}};

}  // namespace

const std::vector<std::string>& posture_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const Posture& p : kPostures) v.emplace_back(p.name);
    return v;
  }();
  return names;
}

Vec3 gravity_for_posture(const std::string& name) {
  for (const Posture& p : kPostures) {
    if (name == p.name) {
      return kStandardGravity_m_s2 * Vec3(p.direction[0], p.direction[1], p.direction[2]);
    }
  }
  std::string accepted;
  for (const std::string& n : posture_names()) accepted += (accepted.empty() ? "" : ", ") + n;
  throw Error("unknown posture '" + name + "'", {}, "accepted postures: " + accepted);
}

}  // namespace vb
