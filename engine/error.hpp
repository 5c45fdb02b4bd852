#pragma once
/// The one error type of VoxBreast: what failed, where, and what to do.
#include <stdexcept>
#include <string>

namespace vb {

class Error : public std::runtime_error {
 public:
  /// what: the problem; where: file/key/line/element (may be empty); hint: what to do (may be empty)
  Error(std::string what, std::string where = {}, std::string hint = {});

  const std::string& problem() const { return problem_; }
  const std::string& location() const { return where_; }
  const std::string& hint() const { return hint_; }

 private:
  std::string problem_, where_, hint_;
};

/// Always-on check (release builds too): throws vb::Error when `ok` is false.
inline void require(bool ok, const std::string& what, const std::string& where = {},
                    const std::string& hint = {}) {
  if (!ok) throw Error(what, where, hint);
}

}  // namespace vb
