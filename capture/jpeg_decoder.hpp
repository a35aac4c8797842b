#pragma once
// MJPEG frames to BGR with libjpeg-turbo, straight into the frame's preallocated image.

#include <cstdint>
#include <span>
#include <string>

#include <opencv2/core.hpp>

namespace surroundd::capture {

class JpegDecoder {
 public:
  JpegDecoder();  // throws CaptureError if libjpeg-turbo cannot start
  ~JpegDecoder();
  JpegDecoder(const JpegDecoder&) = delete;
  JpegDecoder& operator=(const JpegDecoder&) = delete;

  // Decodes into `bgr` (8-bit BGR, already of the picture's size). False, with `error` set, for a
  // picture that is corrupt, truncated or of another size; `bgr` is then not a valid picture.
  bool decode(std::span<const std::uint8_t> jpeg, cv::Mat& bgr, std::string& error);

 private:
  void* handle_;  // tjhandle
};

}  // namespace surroundd::capture
