#pragma once
// One EGL context and renderer per test suite, shared by its tests. Suites derive from it and use
// context_ / renderer_.
#include <gtest/gtest.h>

#include <memory>

#include "render/egl_context.hpp"
#include "render/renderer.hpp"

namespace gvio::test {

class SharedRendererTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    context_ = std::make_unique<render::EglContext>();
    renderer_ = std::make_unique<render::Renderer>(*context_);
  }
  static void TearDownTestSuite() {
    renderer_.reset();
    context_.reset();
  }
  static inline std::unique_ptr<render::EglContext> context_;
  static inline std::unique_ptr<render::Renderer> renderer_;
};

}  // namespace gvio::test
