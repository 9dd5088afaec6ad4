#pragma once

#include <stdexcept>
#include <string>

namespace kerf {

/// A mesh that cannot be read, generated or written: the message names the file and what was
/// expected.
class MeshError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

} // namespace kerf
