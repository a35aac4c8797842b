#pragma once
// Pictures in I420, what H.264 encoders take (render/outputs/video_encoder.hpp): a view made for an
// encoder is converted in the pass that finishes it, while its rows are still in the cache, not in
// one more pass before the encoder.
//
// The layout is cv::COLOR_BGR2YUV_I420's: CV_8UC1 of width x height * 3 / 2, the luma rows, then
// the Cb plane and the Cr plane of (width / 2) x (height / 2) each. BT.601 limited range, as the
// cameras' YUV (common/pixel_format.hpp) and as the encoder tags its streams; each chroma sample is
// that of the mean of its 2x2 pixels (OpenCV takes the top-left one's, which aliases).

#include <opencv2/core.hpp>

#include "processing/stitch/kernel_path.hpp"

namespace surroundd {
class WorkPool;
}

namespace surroundd::processing {

// The cv::Mat size of an I420 picture of `picture` (even sides).
inline cv::Size i420HeldSize(cv::Size picture) { return {picture.width, picture.height * 3 / 2}; }

// Rows [first, last) (both even) of `bgr` (8-bit BGR, even sides) into `i420`, already of
// i420HeldSize(bgr.size()). `path`: every kernel path gives the same bytes (kernel_path.hpp).
void bgrRowsToI420(const cv::Mat& bgr, int first, int last, cv::Mat& i420,
                   KernelPath path = kNativeKernels);

// The whole picture, in parts on `pool`; `i420` is (re)allocated only if it is not already of the
// right size. Throws std::invalid_argument for a picture that is not 8-bit BGR of even sides.
void bgrToI420(const cv::Mat& bgr, cv::Mat& i420, WorkPool& pool);

}  // namespace surroundd::processing
