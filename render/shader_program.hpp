#pragma once
// A linked GLSL ES 3.00 program. Compile and link failures throw RenderError with the program's
// name, the stage and the driver's log.

#include <string>
#include <string_view>

#include <GLES3/gl3.h>

namespace surroundd::render {

class ShaderProgram {
 public:
  ShaderProgram(std::string name, std::string_view vertexSource, std::string_view fragmentSource);
  ~ShaderProgram();
  ShaderProgram(const ShaderProgram&) = delete;
  ShaderProgram& operator=(const ShaderProgram&) = delete;

  GLuint name() const { return program_; }
  // Throws RenderError for a uniform the program does not have (a typo, or optimized away).
  GLint uniform(const char* uniformName) const;

 private:
  std::string name_;
  GLuint program_ = 0;
};

}  // namespace surroundd::render
