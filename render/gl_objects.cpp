#include "render/gl_objects.hpp"

#include <fmt/format.h>

#include "render/render_error.hpp"

namespace gvio::render {

void deleteBuffer(GLuint id) {
  glDeleteBuffers(1, &id);
}
void deleteVertexArray(GLuint id) {
  glDeleteVertexArrays(1, &id);
}
void deleteTexture(GLuint id) {
  glDeleteTextures(1, &id);
}
void deleteFramebuffer(GLuint id) {
  glDeleteFramebuffers(1, &id);
}
void deleteRenderbuffer(GLuint id) {
  glDeleteRenderbuffers(1, &id);
}
void deleteProgram(GLuint id) {
  glDeleteProgram(id);
}

GlBuffer makeBuffer() {
  GLuint id = 0;
  glGenBuffers(1, &id);
  return GlBuffer(id);
}

GlVertexArray makeVertexArray() {
  GLuint id = 0;
  glGenVertexArrays(1, &id);
  return GlVertexArray(id);
}

GlTexture makeTexture() {
  GLuint id = 0;
  glGenTextures(1, &id);
  return GlTexture(id);
}

namespace {

GLuint compile(const std::string& name, GLenum type, const char* source) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    char log[4096] = {};
    glGetShaderInfoLog(shader, sizeof(log), nullptr, log);
    glDeleteShader(shader);
    throw RenderError(fmt::format("shader {} does not compile: {}", name, log));
  }
  return shader;
}

}  // namespace

GlProgram linkProgram(const std::string& name, const char* vertex, const char* fragment,
                      const char* geometry) {
  GlProgram program(glCreateProgram());
  GLuint shaders[3] = {
      compile(name + ".vert", GL_VERTEX_SHADER, vertex),
      compile(name + ".frag", GL_FRAGMENT_SHADER, fragment),
      geometry != nullptr ? compile(name + ".geom", GL_GEOMETRY_SHADER, geometry) : 0};
  for (const GLuint s : shaders) {
    if (s != 0) glAttachShader(program.get(), s);
  }
  glLinkProgram(program.get());
  for (const GLuint s : shaders) {
    if (s != 0) glDeleteShader(s);  // flagged; freed with the program
  }
  GLint ok = GL_FALSE;
  glGetProgramiv(program.get(), GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    char log[4096] = {};
    glGetProgramInfoLog(program.get(), sizeof(log), nullptr, log);
    throw RenderError(fmt::format("shader program {} does not link: {}", name, log));
  }
  return program;
}

void checkGl(const char* where) {
  const GLenum err = glGetError();
  if (err != GL_NO_ERROR) throw RenderError(fmt::format("OpenGL error 0x{:x} in {}", err, where));
}

}  // namespace gvio::render
