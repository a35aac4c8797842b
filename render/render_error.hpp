#pragma once
// Error policy of render/: set-up (EGL, shaders, GL objects) throws RenderError with a message that
// names what failed and the driver's own words (EGL error code, shader log); the per-frame calls
// only throw when the driver reports an error, which ends that output.

#include <stdexcept>

namespace surroundd::render {

class RenderError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace surroundd::render
