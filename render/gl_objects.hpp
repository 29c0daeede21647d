#pragma once
// Move-only owners of OpenGL objects (RAII), and shader program compilation with the driver's log
// in the error message.
#include <epoxy/gl.h>

#include <string>
#include <utility>

namespace gvio::render {

// One GL object name plus the function that deletes it.
template <void (*Delete)(GLuint)>
class GlHandle {
 public:
  GlHandle() = default;
  explicit GlHandle(GLuint id) : id_(id) {}
  ~GlHandle() { reset(); }
  GlHandle(GlHandle&& o) noexcept : id_(std::exchange(o.id_, 0)) {}
  GlHandle& operator=(GlHandle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, 0);
    }
    return *this;
  }
  GlHandle(const GlHandle&) = delete;
  GlHandle& operator=(const GlHandle&) = delete;

  [[nodiscard]] GLuint get() const { return id_; }
  void reset() {
    if (id_ != 0) Delete(id_);
    id_ = 0;
  }

 private:
  GLuint id_ = 0;
};

void deleteBuffer(GLuint id);
void deleteVertexArray(GLuint id);
void deleteTexture(GLuint id);
void deleteFramebuffer(GLuint id);
void deleteRenderbuffer(GLuint id);
void deleteProgram(GLuint id);

using GlBuffer = GlHandle<deleteBuffer>;
using GlVertexArray = GlHandle<deleteVertexArray>;
using GlTexture = GlHandle<deleteTexture>;
using GlFramebuffer = GlHandle<deleteFramebuffer>;
using GlRenderbuffer = GlHandle<deleteRenderbuffer>;
using GlProgram = GlHandle<deleteProgram>;

GlBuffer makeBuffer();
GlVertexArray makeVertexArray();
GlTexture makeTexture();

// Compiles and links; `geometry` may be empty. Throws RenderError with the info log.
GlProgram linkProgram(const std::string& name, const char* vertex, const char* fragment,
                      const char* geometry = nullptr);

// Throws RenderError naming `where` when glGetError reports anything.
void checkGl(const char* where);

}  // namespace gvio::render
