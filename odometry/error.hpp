#pragma once
// The one exception type that means "the user's input or configuration is wrong" (CLI exit 2).
// Anything else that escapes to main() is an internal error (exit 1).
#include <stdexcept>
#include <string>

namespace gvio {

class InvalidInput : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace gvio
