#include "render/outputs/jpeg_encoder.hpp"

#include <fmt/format.h>
#include <turbojpeg.h>

#include "render/render_error.hpp"

namespace surroundd::render {

JpegEncoder::JpegEncoder(int quality) : handle_(tjInitCompress()), quality_(quality) {
  if (handle_ == nullptr) throw RenderError("libjpeg-turbo: cannot create a compressor");
}

JpegEncoder::~JpegEncoder() { tjDestroy(handle_); }

std::size_t JpegEncoder::encode(const cv::Mat& bgr, std::vector<unsigned char>& jpeg) {
  if (bgr.type() != CV_8UC3 || bgr.empty()) {
    throw RenderError(
        fmt::format("JPEG encoding: expected an 8-bit BGR picture, got type {} of {}x{}",
                    bgr.type(), bgr.cols, bgr.rows));
  }
  const unsigned long worstCase = tjBufSize(bgr.cols, bgr.rows, TJSAMP_420);
  if (jpeg.size() < worstCase) jpeg.resize(worstCase);
  unsigned char* out = jpeg.data();
  unsigned long size = jpeg.size();
  // NOREALLOC: libjpeg-turbo writes into our buffer, which holds its worst case, and never frees
  // or replaces it.
  if (tjCompress2(handle_, bgr.data, bgr.cols, static_cast<int>(bgr.step), bgr.rows, TJPF_BGR, &out,
                  &size, TJSAMP_420, quality_, TJFLAG_NOREALLOC | TJFLAG_FASTDCT) != 0) {
    throw RenderError(fmt::format("JPEG encoding of a {}x{} picture failed: {}", bgr.cols, bgr.rows,
                                  tjGetErrorStr2(handle_)));
  }
  return size;
}

}  // namespace surroundd::render
