#pragma once
// Rendering failures. No usable EGL/GL context is the user's environment (CLI exit 2); a bad
// scene or size request is bad input (exit 2) too, so both derive from InvalidInput.
#include "odometry/error.hpp"

namespace gvio::render {

class RenderError : public InvalidInput {
 public:
  using InvalidInput::InvalidInput;
};

}  // namespace gvio::render
