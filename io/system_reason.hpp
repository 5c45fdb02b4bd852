#pragma once
/// The operating system's reason for a failed call, as a message ends in it.
#include <string>

namespace vb {

/// strerror(errnum) starting in lower case, for one-line messages ("no space left on device").
std::string system_reason(int errnum);

}  // namespace vb
