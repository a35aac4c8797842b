#include "common/pixel_format.hpp"

#include <opencv2/imgproc.hpp>

namespace surroundd {
namespace {

// Each chroma sample is that of the mean of the pixels sharing it (YUYV, UYVY: two in a row; NV12:
// 2x2).
// Computed here rather than by libswscale, whose packed 4:2:2 output comes out a level and a half
// too blue and red against decoded frames; plain float arithmetic: this is for start-up and tests.
std::uint8_t level(float value) { return cv::saturate_cast<std::uint8_t>(value); }
float lumaOf(const cv::Vec3f& bgr) {
  return 16.0F + (24.966F * bgr[0] + 128.553F * bgr[1] + 65.481F * bgr[2]) / 255.0F;
}
float cbOf(const cv::Vec3f& bgr) {
  return 128.0F + (112.0F * bgr[0] - 74.203F * bgr[1] - 37.797F * bgr[2]) / 255.0F;
}
float crOf(const cv::Vec3f& bgr) {
  return 128.0F + (-18.214F * bgr[0] - 93.786F * bgr[1] + 112.0F * bgr[2]) / 255.0F;
}

// Packed 4:2:2, its luma first (YUYV: Y0 Cb Y1 Cr) or its chroma first (UYVY: Cb Y0 Cr Y1).
void writePacked422(const cv::Mat& bgr, bool lumaFirst, std::uint8_t* out) {
  const int luma = lumaFirst ? 0 : 1;
  const int chroma = 1 - luma;
  for (int y = 0; y < bgr.rows; ++y) {
    const auto* row = bgr.ptr<cv::Vec3b>(y);
    for (int x = 0; x < bgr.cols; x += 2, out += 4) {
      const cv::Vec3f left = row[x];
      const cv::Vec3f right = row[x + 1];
      const cv::Vec3f mean = (left + right) * 0.5F;
      out[luma] = level(lumaOf(left));
      out[chroma] = level(cbOf(mean));
      out[luma + 2] = level(lumaOf(right));
      out[chroma + 2] = level(crOf(mean));
    }
  }
}

void writeNv12(const cv::Mat& bgr, std::uint8_t* out) {
  std::uint8_t* chroma = out + bgr.total();
  for (int y = 0; y < bgr.rows; y += 2) {
    const auto* top = bgr.ptr<cv::Vec3b>(y);
    const auto* bottom = bgr.ptr<cv::Vec3b>(y + 1);
    std::uint8_t* lumaTop = out + static_cast<std::size_t>(y) * bgr.cols;
    std::uint8_t* lumaBottom = lumaTop + bgr.cols;
    for (int x = 0; x < bgr.cols; x += 2, chroma += 2) {
      const cv::Vec3f a = top[x], b = top[x + 1], c = bottom[x], d = bottom[x + 1];
      lumaTop[x] = level(lumaOf(a));
      lumaTop[x + 1] = level(lumaOf(b));
      lumaBottom[x] = level(lumaOf(c));
      lumaBottom[x + 1] = level(lumaOf(d));
      const cv::Vec3f mean = (a + b + c + d) * 0.25F;
      chroma[0] = level(cbOf(mean));
      chroma[1] = level(crOf(mean));
    }
  }
}

}  // namespace

const char* toString(PixelFormat format) {
  switch (format) {
    case PixelFormat::kBgr:
      return "BGR";
    case PixelFormat::kYuyv:
      return "YUYV";
    case PixelFormat::kUyvy:
      return "UYVY";
    case PixelFormat::kNv12:
      return "NV12";
  }
  return "?";
}

int heldType(PixelFormat format) {
  switch (format) {
    case PixelFormat::kYuyv:
    case PixelFormat::kUyvy:
      return CV_8UC2;
    case PixelFormat::kNv12:
      return CV_8UC1;
    case PixelFormat::kBgr:
      break;
  }
  return CV_8UC3;
}

cv::Size heldSize(PixelFormat format, cv::Size pictureSize) {
  if (format == PixelFormat::kNv12) return {pictureSize.width, pictureSize.height * 3 / 2};
  return pictureSize;
}

cv::Size pictureSize(PixelFormat format, const cv::Mat& held) {
  if (format == PixelFormat::kNv12) return {held.cols, held.rows * 2 / 3};
  return held.size();
}

bool holds(const cv::Mat& held, PixelFormat format, cv::Size size) {
  return held.type() == heldType(format) && held.size() == heldSize(format, size) &&
         held.isContinuous();
}

cv::Mat blackPicture(PixelFormat format, cv::Size size) {
  const cv::Size held = heldSize(format, size);
  switch (format) {
    case PixelFormat::kBgr:
      break;
    case PixelFormat::kYuyv:
      return {held, CV_8UC2, cv::Scalar(16, 128)};
    case PixelFormat::kUyvy:
      return {held, CV_8UC2, cv::Scalar(128, 16)};
    case PixelFormat::kNv12: {
      cv::Mat picture(held, CV_8UC1, cv::Scalar(128));
      picture.rowRange(0, size.height).setTo(16);
      return picture;
    }
  }
  return {held, CV_8UC3, cv::Scalar::all(0)};
}

void heldToBgr(const cv::Mat& held, PixelFormat format, cv::Mat& bgr) {
  switch (format) {
    case PixelFormat::kBgr:
      held.copyTo(bgr);
      return;
    case PixelFormat::kYuyv:
      cv::cvtColor(held, bgr, cv::COLOR_YUV2BGR_YUYV);
      return;
    case PixelFormat::kUyvy:
      cv::cvtColor(held, bgr, cv::COLOR_YUV2BGR_UYVY);
      return;
    case PixelFormat::kNv12:
      cv::cvtColor(held, bgr, cv::COLOR_YUV2BGR_NV12);
      return;
  }
}

void bgrToHeld(const cv::Mat& bgr, PixelFormat format, cv::Mat& held) {
  held.create(heldSize(format, bgr.size()), heldType(format));
  switch (format) {
    case PixelFormat::kBgr:
      bgr.copyTo(held);
      return;
    case PixelFormat::kYuyv:
    case PixelFormat::kUyvy:
      writePacked422(bgr, format == PixelFormat::kYuyv, held.ptr<std::uint8_t>());
      return;
    case PixelFormat::kNv12:
      writeNv12(bgr, held.ptr<std::uint8_t>());
      return;
  }
}

}  // namespace surroundd
