#include "engine/error.hpp"

namespace vb {
namespace {
std::string compose(const std::string& what, const std::string& where, const std::string& hint) {
  std::string s;  // appended piece by piece: GCC 12 warns falsely on chained + at -O3
  if (!where.empty()) s.append(where).append(": ");
  s.append(what);
  if (!hint.empty()) s.append(" (").append(hint).append(")");
  return s;
}
}  // namespace

Error::Error(std::string what, std::string where, std::string hint)
    : std::runtime_error(compose(what, where, hint)),
      problem_(std::move(what)),
      where_(std::move(where)),
      hint_(std::move(hint)) {}

}  // namespace vb
