#include "render/outputs/encoder_conversion.hpp"

#include <cstdint>
#include <stdexcept>

#include "render/outputs/frame_sink.hpp"

extern "C" {
#include <libswscale/swscale.h>
}

namespace surroundd::render {

EncoderConversion::EncoderConversion(cv::Size size, AVPixelFormat frameFormat) : size_(size) {
  const bool subsampled = frameFormat == AV_PIX_FMT_YUV420P || frameFormat == AV_PIX_FMT_NV12;
  // To 4:2:0, swscale's accurate rounding would take its generic scaler (2.7 ms a 1280x720
  // picture, measured here) where its unscaled BGR -> YUV 4:2:0 conversion takes 0.7-0.9 ms, for
  // at most a level of luma and a few of chroma, well under what H.264 itself changes.
  const int accuracy = subsampled ? 0 : SWS_ACCURATE_RND | SWS_FULL_CHR_H_INT;
  const auto from = [&](AVPixelFormat format, int flags) {
    ffmpeg::SwsContextPtr context(sws_getContext(size.width, size.height, format, size.width,
                                                 size.height, frameFormat, flags, nullptr, nullptr,
                                                 nullptr));
    if (!context) throw std::runtime_error("cannot set up the colour conversion");
    return context;
  };
  fromBgr_ = from(AV_PIX_FMT_BGR24, SWS_BICUBIC | SWS_BITEXACT | accuracy);
  if (frameFormat != AV_PIX_FMT_BGR24) {
    const int* bt601 = sws_getCoefficients(SWS_CS_ITU601);
    sws_setColorspaceDetails(fromBgr_.get(), bt601, 1, bt601, 0, 0, 1 << 16, 1 << 16);
  }
  if (subsampled) fromI420_ = from(AV_PIX_FMT_YUV420P, SWS_POINT | SWS_BITEXACT);
}

bool EncoderConversion::convert(const cv::Mat& picture, AVFrame& frame) const {
  const bool i420 = fromI420_ && isI420(picture, size_);
  if (!i420 && (picture.type() != CV_8UC3 || picture.size() != size_)) return false;
  const std::size_t luma = size_.area();
  const std::uint8_t* source[] = {picture.data, picture.data + luma, picture.data + luma * 5 / 4};
  const int sourceStride[] = {static_cast<int>(picture.step[0]), size_.width / 2, size_.width / 2};
  sws_scale(i420 ? fromI420_.get() : fromBgr_.get(), source, sourceStride, 0, size_.height,
            frame.data, frame.linesize);
  return true;
}

}  // namespace surroundd::render
