#pragma once
// BGR pictures to JPEG with libjpeg-turbo, into a caller's buffer that is kept between calls: once
// it has held the largest picture's worst case, encoding allocates nothing.

#include <cstddef>
#include <vector>

#include <opencv2/core.hpp>

namespace surroundd::render {

class JpegEncoder {
 public:
  explicit JpegEncoder(int quality);  // 1..100; throws RenderError if libjpeg-turbo cannot start
  ~JpegEncoder();
  JpegEncoder(const JpegEncoder&) = delete;
  JpegEncoder& operator=(const JpegEncoder&) = delete;

  // Encodes `bgr` (8-bit BGR, 4:2:0) into the start of `jpeg` and returns its length. `jpeg` is
  // grown to libjpeg-turbo's worst case for the picture's size if it is smaller, never shrunk.
  // Throws RenderError if libjpeg-turbo fails.
  std::size_t encode(const cv::Mat& bgr, std::vector<unsigned char>& jpeg);

 private:
  void* handle_;  // tjhandle
  int quality_;
};

}  // namespace surroundd::render
