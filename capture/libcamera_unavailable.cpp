// Built instead of libcamera_source.cpp where SURROUNDD_WITH_LIBCAMERA is off
// (cmake/OptionalParts.cmake).
#include <fmt/format.h>

#include "capture/libcamera_source.hpp"
#include "common/build_info.hpp"

namespace surroundd::capture {

bool libcameraAvailable() { return false; }

std::vector<std::string> libcameraCameras() {
  throw CaptureError("this surroundd was built without libcamera");
}

struct LibcameraSource::Impl {};

LibcameraSource::LibcameraSource(std::string cameraName, LibcameraSettings /*settings*/) {
  throw CaptureError(fmt::format("camera '{}': this surroundd was built without libcamera ({})",
                                 cameraName, howToBuildIn("LIBCAMERA")));
}

LibcameraSource::~LibcameraSource() = default;
cv::Size LibcameraSource::frameSize() const { return {}; }
PixelFormat LibcameraSource::pixelFormat() const { return PixelFormat::kBgr; }
Timestamp LibcameraSource::nominalPeriod() const { return {}; }
ReadStatus LibcameraSource::read(Frame& /*out*/) { return ReadStatus::kEndOfStream; }
void LibcameraSource::reopen() { throw CaptureError("built without libcamera"); }
const std::string& LibcameraSource::lastError() const {
  static const std::string kNone;
  return kNone;
}

}  // namespace surroundd::capture
