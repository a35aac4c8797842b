#include "render/gl_objects.hpp"

#include <fmt/core.h>

#include "render/render_error.hpp"

namespace surroundd::render::gl {

void check(const char* what) {
  const GLenum error = glGetError();
  if (error != GL_NO_ERROR) {
    // Clear any further queued errors so the next check reports only its own.
    while (glGetError() != GL_NO_ERROR) {
    }
    throw RenderError(fmt::format("OpenGL ES error 0x{:04x} while {}", error, what));
  }
}

}  // namespace surroundd::render::gl
