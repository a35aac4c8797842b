#include "render/outputs/view_blit.hpp"

#include <algorithm>

#include "render/gl_objects.hpp"

namespace surroundd::render {

void blitView(GLuint framebuffer, cv::Size view, cv::Size target) {
  const double scale = std::min(static_cast<double>(target.width) / view.width,
                                static_cast<double>(target.height) / view.height);
  const cv::Size fitted(static_cast<int>(view.width * scale),
                        static_cast<int>(view.height * scale));
  const cv::Point at((target.width - fitted.width) / 2, (target.height - fitted.height) / 2);
  if (fitted != target) {
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT);
  }
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer);
  // `at` counts from the top; the surface's rows from its bottom.
  const int top = target.height - at.y;
  glBlitFramebuffer(0, 0, view.width, view.height, at.x, top, at.x + fitted.width,
                    top - fitted.height, GL_COLOR_BUFFER_BIT,
                    fitted == view ? GL_NEAREST : GL_LINEAR);
  gl::check("copying a view to the screen");
}

}  // namespace surroundd::render
