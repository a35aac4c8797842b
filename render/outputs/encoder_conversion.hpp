#pragma once
// The colour conversion of a VideoEncoder (video_encoder.hpp): each picture it is handed, 8-bit BGR
// or I420 (frame_sink.hpp), into the frame it encodes, by libswscale. BGR to YUV is BT.601 limited
// range, as the encoder tags its streams; an I420 picture is only copied (or interleaved, for an
// encoder that takes NV12), as its maker already converted it.
//
// Error policy: the constructor throws std::runtime_error when libswscale cannot convert; convert()
// returns false for a picture of another size or type, for the encoder to name its stream.

#include <opencv2/core.hpp>

#include "common/ffmpeg_util.hpp"

namespace surroundd::render {

class EncoderConversion {
 public:
  // Pictures of `size` into frames of `frameFormat`; `bgr24` (libx264rgb) keeps BGR's full range.
  EncoderConversion(cv::Size size, AVPixelFormat frameFormat);

  // Whether I420 pictures are taken: the frames are 4:2:0 (I420 or NV12).
  bool takesI420() const { return static_cast<bool>(fromI420_); }
  // `picture` into `frame` (allocated, writable, of the size and format above).
  bool convert(const cv::Mat& picture, AVFrame& frame) const;

 private:
  cv::Size size_;
  ffmpeg::SwsContextPtr fromBgr_;
  ffmpeg::SwsContextPtr fromI420_;  // null where the frames are not 4:2:0
};

}  // namespace surroundd::render
