#include "render/gl_objects.hpp"

#include <fmt/core.h>

#include "render/render_error.hpp"

namespace surroundd::render::gl {

bool hasExtension(std::string_view name) {
  GLint count = 0;
  glGetIntegerv(GL_NUM_EXTENSIONS, &count);
  for (GLint i = 0; i < count; ++i) {
    const auto* extension = reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, i));
    if (extension != nullptr && name == extension) return true;
  }
  return false;
}

void check(const char* what) {
  const GLenum error = glGetError();
  if (error != GL_NO_ERROR) {
    // Clear any further queued errors so the next check reports only its own.
    while (glGetError() != GL_NO_ERROR) {
    }
    throw RenderError(fmt::format("OpenGL ES error 0x{:04x} while {}", error, what));
  }
}

void Fence::place() {
  glDeleteSync(sync_);
  sync_ = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
  glFlush();
}

bool Fence::passed() const {
  if (sync_ == nullptr) return true;
  const GLenum state = glClientWaitSync(sync_, 0, 0);
  return state == GL_ALREADY_SIGNALED || state == GL_CONDITION_SATISFIED;
}

}  // namespace surroundd::render::gl
