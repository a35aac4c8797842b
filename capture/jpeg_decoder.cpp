#include "capture/jpeg_decoder.hpp"

#include <fmt/format.h>
#include <turbojpeg.h>

#include "capture/frame_source.hpp"

namespace surroundd::capture {

JpegDecoder::JpegDecoder() : handle_(tjInitDecompress()) {
  if (handle_ == nullptr) throw CaptureError("libjpeg-turbo: cannot create a decompressor");
}

JpegDecoder::~JpegDecoder() { tjDestroy(handle_); }

bool JpegDecoder::decode(std::span<const std::uint8_t> jpeg, cv::Mat& bgr, std::string& error) {
  int width = 0;
  int height = 0;
  int subsampling = 0;
  int colourspace = 0;
  if (jpeg.size() < 4 ||
      tjDecompressHeader3(handle_, jpeg.data(), static_cast<unsigned long>(jpeg.size()), &width,
                          &height, &subsampling, &colourspace) != 0) {
    error = fmt::format("corrupt MJPEG frame ({} bytes): {}", jpeg.size(),
                        jpeg.size() < 4 ? "too short" : tjGetErrorStr2(handle_));
    return false;
  }
  if (width != bgr.cols || height != bgr.rows) {
    error = fmt::format("MJPEG frame of {}x{} where {}x{} was negotiated", width, height, bgr.cols,
                        bgr.rows);
    return false;
  }
  // A truncated picture decodes with a warning into grey blocks: that is a fault too.
  if (tjDecompress2(handle_, jpeg.data(), static_cast<unsigned long>(jpeg.size()), bgr.data, width,
                    static_cast<int>(bgr.step), height, TJPF_BGR, TJFLAG_FASTDCT) != 0) {
    error = fmt::format("corrupt MJPEG frame ({} bytes): {}", jpeg.size(), tjGetErrorStr2(handle_));
    return false;
  }
  return true;
}

}  // namespace surroundd::capture
