#pragma once
// A problem with the model a user set up (not a bug and not an I/O failure): unconstrained
// statics, a penalty too low for a positive definite stiffness, a load or probe that
// cannot be placed. The dgtex tool maps it to exit code 2.
// An exception value type (owns its message).
#include <stdexcept>
#include <string>

namespace dgtex {

class ModelError : public std::runtime_error {
 public:
  explicit ModelError(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace dgtex
