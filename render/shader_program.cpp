#include "render/shader_program.hpp"

#include <algorithm>
#include <string>

#include <fmt/core.h>

#include "render/render_error.hpp"

namespace surroundd::render {
namespace {

// A shader's or program's info log, through the matching pair of queries.
std::string infoLog(GLuint object, void (*parameter)(GLuint, GLenum, GLint*),
                    void (*log)(GLuint, GLsizei, GLsizei*, GLchar*)) {
  GLint length = 0;
  parameter(object, GL_INFO_LOG_LENGTH, &length);
  std::string text(static_cast<std::size_t>(std::max(length, 1)), '\0');
  GLsizei written = 0;
  log(object, length, &written, text.data());
  text.resize(static_cast<std::size_t>(written));
  return text;
}

// Returns the compiled shader; the caller deletes it once the program is linked.
GLuint compile(const std::string& program, GLenum stage, std::string_view source) {
  const GLuint shader = glCreateShader(stage);
  const char* text = source.data();
  const auto length = static_cast<GLint>(source.size());
  glShaderSource(shader, 1, &text, &length);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    const std::string log = infoLog(shader, glGetShaderiv, glGetShaderInfoLog);
    glDeleteShader(shader);
    throw RenderError(fmt::format("shader program '{}': {} shader does not compile: {}", program,
                                  stage == GL_VERTEX_SHADER ? "vertex" : "fragment", log));
  }
  return shader;
}

}  // namespace

ShaderProgram::ShaderProgram(std::string name, std::string_view vertexSource,
                             std::string_view fragmentSource)
    : name_(std::move(name)) {
  const GLuint vertex = compile(name_, GL_VERTEX_SHADER, vertexSource);
  GLuint fragment = 0;
  try {
    fragment = compile(name_, GL_FRAGMENT_SHADER, fragmentSource);
  } catch (...) {
    glDeleteShader(vertex);
    throw;
  }
  program_ = glCreateProgram();
  glAttachShader(program_, vertex);
  glAttachShader(program_, fragment);
  glLinkProgram(program_);
  glDeleteShader(vertex);  // flagged; freed with the program
  glDeleteShader(fragment);
  GLint ok = GL_FALSE;
  glGetProgramiv(program_, GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    const std::string log = infoLog(program_, glGetProgramiv, glGetProgramInfoLog);
    glDeleteProgram(program_);
    throw RenderError(fmt::format("shader program '{}' does not link: {}", name_, log));
  }
}

ShaderProgram::~ShaderProgram() { glDeleteProgram(program_); }

GLint ShaderProgram::uniform(const char* uniformName) const {
  const GLint location = glGetUniformLocation(program_, uniformName);
  if (location < 0) {
    throw RenderError(fmt::format("shader program '{}' has no uniform '{}'", name_, uniformName));
  }
  return location;
}

}  // namespace surroundd::render
