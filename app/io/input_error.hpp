#pragma once
// Bad input found while reading a file: "path:line: message" (line 0 = the file as a whole).
#include <cstddef>
#include <filesystem>
#include <string>

#include "odometry/error.hpp"

namespace gvio::io {

class InputError : public InvalidInput {
 public:
  InputError(const std::filesystem::path& file, std::size_t line, const std::string& message);
};

}  // namespace gvio::io
