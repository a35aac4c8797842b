// The MJPEG decode path (JpegDecoder, libjpeg-turbo) on any bytes: a picture or false with a
// message. The target image has the size the JPEG's header claims (bounded, as a camera's frame
// pool is), so that decoding goes past the size check; a second decode into a wrong size must be
// refused, not written past.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include <opencv2/core.hpp>
#include <turbojpeg.h>

#include "capture/jpeg_decoder.hpp"
#include "tests/fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  surroundd::fuzz::quietLogs();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static surroundd::capture::JpegDecoder decoder;
  static const tjhandle header = tjInitDecompress();
  const std::span<const std::uint8_t> jpeg(data, size);
  std::string error;
  int width = 64, height = 48, subsampling = 0, colourspace = 0;
  if (tjDecompressHeader3(header, data, static_cast<unsigned long>(size), &width, &height,
                          &subsampling, &colourspace) != 0 ||
      width < 1 || height < 1 || width > 4096 || height > 4096) {
    width = 64;
    height = 48;
  }
  // A camera's frame buffer is written in place, never replaced: the pool owns it.
  cv::Mat bgr(height, width, CV_8UC3);
  const auto* const buffer = bgr.data;
  const bool decoded = decoder.decode(jpeg, bgr, error);
  FUZZ_CHECK(bgr.data == buffer && bgr.rows == height && bgr.cols == width);
  FUZZ_CHECK(decoded || !error.empty());  // a refusal says why
  error.clear();
  cv::Mat smaller(height / 2 + 1, width / 2 + 1, CV_8UC3);
  const bool decodedSmaller = decoder.decode(jpeg, smaller, error);
  FUZZ_CHECK(!(decoded && decodedSmaller));  // a picture of another size must be refused
  FUZZ_CHECK(decodedSmaller || !error.empty());
  return 0;
}
