#pragma once
// Owning handles for OpenGL ES objects: made on construction, deleted on destruction, movable and
// not copyable. They must live and die on the thread where the EglContext is current.

#include <string_view>
#include <utility>

#include <GLES3/gl3.h>

namespace surroundd::render::gl {

template <typename Kind>
class Object {
 public:
  Object() { Kind::create(1, &name_); }
  ~Object() {
    if (name_ != 0) Kind::destroy(1, &name_);
  }
  Object(Object&& other) noexcept : name_(std::exchange(other.name_, 0)) {}
  Object& operator=(Object&& other) noexcept {
    std::swap(name_, other.name_);
    return *this;
  }
  Object(const Object&) = delete;
  Object& operator=(const Object&) = delete;

  GLuint name() const { return name_; }

 private:
  GLuint name_ = 0;
};

struct TextureKind {
  static void create(GLsizei n, GLuint* names) { glGenTextures(n, names); }
  static void destroy(GLsizei n, const GLuint* names) { glDeleteTextures(n, names); }
};
struct BufferKind {
  static void create(GLsizei n, GLuint* names) { glGenBuffers(n, names); }
  static void destroy(GLsizei n, const GLuint* names) { glDeleteBuffers(n, names); }
};
struct FramebufferKind {
  static void create(GLsizei n, GLuint* names) { glGenFramebuffers(n, names); }
  static void destroy(GLsizei n, const GLuint* names) { glDeleteFramebuffers(n, names); }
};
struct RenderbufferKind {
  static void create(GLsizei n, GLuint* names) { glGenRenderbuffers(n, names); }
  static void destroy(GLsizei n, const GLuint* names) { glDeleteRenderbuffers(n, names); }
};
struct VertexArrayKind {
  static void create(GLsizei n, GLuint* names) { glGenVertexArrays(n, names); }
  static void destroy(GLsizei n, const GLuint* names) { glDeleteVertexArrays(n, names); }
};

// A fence in the command stream: passed once every command issued before it has completed.
class Fence {
 public:
  Fence() = default;
  ~Fence() { glDeleteSync(sync_); }  // none placed: a null sync, which GL ignores
  Fence(Fence&& other) noexcept : sync_(std::exchange(other.sync_, nullptr)) {}
  Fence& operator=(Fence&& other) noexcept {
    std::swap(sync_, other.sync_);
    return *this;
  }
  Fence(const Fence&) = delete;
  Fence& operator=(const Fence&) = delete;

  // After the commands issued so far, in place of the last one; flushed, so that it passes
  // without another GL call.
  void place();
  // Whether it has passed, without waiting; true where none was placed.
  bool passed() const;

 private:
  GLsync sync_ = nullptr;
};

using Texture = Object<TextureKind>;
using Buffer = Object<BufferKind>;
using Framebuffer = Object<FramebufferKind>;
using Renderbuffer = Object<RenderbufferKind>;
using VertexArray = Object<VertexArrayKind>;

// Whether the current context's driver has the extension `name` ("GL_EXT_disjoint_timer_query").
bool hasExtension(std::string_view name);

// Throws RenderError naming `what` if GL has recorded an error since the last check.
void check(const char* what);

}  // namespace surroundd::render::gl
