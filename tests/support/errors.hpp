#pragma once
// Assertions on the one-line input errors every reader produces ("file:line: message").
#include <gtest/gtest.h>

#include <cstddef>
#include <filesystem>
#include <string>

#include "io/input_error.hpp"

namespace gvio::test {

// The what() of the io::InputError `fn` throws, or "" (with a test failure) when it throws none.
template <typename Fn>
std::string inputError(Fn&& fn) {
  try {
    fn();
  } catch (const io::InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an InputError";
  return {};
}

// True when `message` is "<file>[:<line>]: ..." (line 0: no line) and mentions `phrase`.
inline ::testing::AssertionResult names(const std::string& message,
                                        const std::filesystem::path& file, std::size_t line,
                                        const std::string& phrase) {
  const std::string where = file.string() + (line > 0 ? ":" + std::to_string(line) : "") + ": ";
  if (!message.starts_with(where)) {
    return ::testing::AssertionFailure()
           << "'" << message << "' does not start with '" << where << "'";
  }
  if (message.find(phrase) == std::string::npos) {
    return ::testing::AssertionFailure() << "'" << message << "' lacks '" << phrase << "'";
  }
  return ::testing::AssertionSuccess();
}

}  // namespace gvio::test
