#pragma once
// A surround view's picture copied on the GPU into what a display shows (an EGL window surface, a
// GBM surface): into the framebuffer bound for drawing, fitted to its size keeping the view's
// aspect, with black bars around it. The view's row 0 is the picture's top; a surface's is its
// bottom, so the copy flips it.

#include <GLES3/gl3.h>
#include <opencv2/core/types.hpp>

namespace surroundd::render {

// Reads from `framebuffer` (the view's, of `view` size); leaves it bound for reading. Needs a
// current context; throws RenderError on a GL error.
void blitView(GLuint framebuffer, cv::Size view, cv::Size target);

}  // namespace surroundd::render
