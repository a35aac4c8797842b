#pragma once
// An in-process V4L2 device for tests: it answers the ioctls the V4L2 source makes the way a
// driver does (formats and sizes to enumerate, MMAP buffers, a queue), produces frames of a
// synthetic picture in the negotiated format with monotonic timestamps, and fails on request:
// unplugged (ENODEV, then open fails until plugged back), stalled (poll times out without
// waiting), corrupt MJPEG.
//
// The test keeps a FakeV4l2Device::State to steer the device after handing the device to a
// source.

#include <cerrno>
#include <cstring>
#include <deque>
#include <functional>
#include <memory>
#include <vector>

#include <fcntl.h>
#include <linux/videodev2.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "capture/v4l2_device.hpp"

namespace surroundd::testing {

// BGR to packed 4:2:2 (YUYV or UYVY), BT.601 limited range like OpenCV's conversion back.
inline std::vector<std::uint8_t> packedYuv(const cv::Mat& bgr, bool yuyv) {
  cv::Mat yuv;
  cv::cvtColor(bgr, yuv, cv::COLOR_BGR2YCrCb);  // full-range; adjust to limited below
  std::vector<std::uint8_t> out(static_cast<std::size_t>(bgr.total()) * 2);
  const auto limitedY = [](int y) { return static_cast<std::uint8_t>(16 + y * 219 / 255); };
  const auto limitedC = [](int c) {
    return static_cast<std::uint8_t>(128 + (c - 128) * 224 / 255);
  };
  for (int r = 0; r < bgr.rows; ++r) {
    for (int c = 0; c < bgr.cols; c += 2) {
      const auto a = yuv.at<cv::Vec3b>(r, c);
      const auto b = yuv.at<cv::Vec3b>(r, c + 1);
      const std::uint8_t y0 = limitedY(a[0]), y1 = limitedY(b[0]);
      const std::uint8_t cr = limitedC((a[1] + b[1]) / 2), cb = limitedC((a[2] + b[2]) / 2);
      std::uint8_t* p = out.data() + (static_cast<std::size_t>(r) * bgr.cols + c) * 2;
      if (yuyv) {
        p[0] = y0, p[1] = cb, p[2] = y1, p[3] = cr;
      } else {
        p[0] = cb, p[1] = y0, p[2] = cr, p[3] = y1;
      }
    }
  }
  return out;
}

inline std::vector<std::uint8_t> nv12(const cv::Mat& bgr) {
  cv::Mat i420;
  cv::cvtColor(bgr, i420, cv::COLOR_BGR2YUV_I420);
  const std::size_t luma = bgr.total();
  const std::size_t chroma = luma / 4;
  std::vector<std::uint8_t> out(luma + 2 * chroma);
  std::memcpy(out.data(), i420.data, luma);
  for (std::size_t i = 0; i < chroma; ++i) {
    out[luma + 2 * i] = i420.data[luma + i];               // U
    out[luma + 2 * i + 1] = i420.data[luma + chroma + i];  // V
  }
  return out;
}

class FakeV4l2Device final : public surroundd::capture::V4l2Device {
 public:
  struct Mode {
    std::uint32_t fourcc;
    cv::Size size;
  };
  struct State {
    std::vector<Mode> modes;
    std::vector<v4l2_queryctrl> controls;
    std::vector<v4l2_control> controlsSet;
    bool plugged = true;
    int stalledPolls = 0;        // the next polls time out
    bool corruptNext = false;    // the next MJPEG frame is cut short
    bool exportsDmabuf = false;  // VIDIOC_EXPBUF answers (with /dev/null descriptors)
    int opens = 0;
    std::uint64_t produced = 0;
    std::int64_t firstTimestampUs = 1'000'000;
    std::int64_t periodUs = 33'333;
    std::function<cv::Mat(std::uint64_t frame, cv::Size size)> picture;
  };

  explicit FakeV4l2Device(std::shared_ptr<State> state) : state_(std::move(state)) {}

  int open(const std::string&) override {
    if (!state_->plugged) return ENOENT;
    ++state_->opens;
    open_ = true;
    return 0;
  }
  void close() override {
    open_ = false;
    streaming_ = false;
    buffers_.clear();
    queue_.clear();
  }
  void* map(std::size_t length, std::int64_t offset) override {
    const auto index = static_cast<std::size_t>(offset >> 16);
    if (index >= buffers_.size() || buffers_[index].size() != length) return nullptr;
    return buffers_[index].data();
  }
  void unmap(void*, std::size_t) override {}
  int waitReadable(std::chrono::milliseconds) override {
    if (!state_->plugged) return ENODEV;
    if (state_->stalledPolls > 0) {
      --state_->stalledPolls;
      return ETIMEDOUT;
    }
    return streaming_ && !queue_.empty() ? 0 : ETIMEDOUT;
  }

  int ioctl(unsigned long request, void* argument) override {
    if (!open_) return EBADF;
    if (!state_->plugged) return ENODEV;
    switch (request) {
      case VIDIOC_QUERYCAP: {
        auto* caps = static_cast<v4l2_capability*>(argument);
        *caps = {};
        std::strcpy(reinterpret_cast<char*>(caps->driver), "fake");
        std::strcpy(reinterpret_cast<char*>(caps->card), "Fake camera");
        caps->capabilities = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
        return 0;
      }
      case VIDIOC_ENUM_FMT: {
        auto* description = static_cast<v4l2_fmtdesc*>(argument);
        const auto fourccs = distinctFourccs();
        if (description->index >= fourccs.size()) return EINVAL;
        description->pixelformat = fourccs[description->index];
        return 0;
      }
      case VIDIOC_ENUM_FRAMESIZES: {
        auto* size = static_cast<v4l2_frmsizeenum*>(argument);
        std::uint32_t k = 0;
        for (const auto& mode : state_->modes) {
          if (mode.fourcc != size->pixel_format) continue;
          if (k++ == size->index) {
            size->type = V4L2_FRMSIZE_TYPE_DISCRETE;
            size->discrete = {static_cast<std::uint32_t>(mode.size.width),
                              static_cast<std::uint32_t>(mode.size.height)};
            return 0;
          }
        }
        return EINVAL;
      }
      case VIDIOC_S_FMT: {
        auto& pix = static_cast<v4l2_format*>(argument)->fmt.pix;
        // Like a driver: an unsupported request is adjusted to the first mode, not refused.
        Mode mode = state_->modes.front();
        for (const auto& m : state_->modes) {
          if (m.fourcc == pix.pixelformat &&
              m.size == cv::Size(static_cast<int>(pix.width), static_cast<int>(pix.height))) {
            mode = m;
          }
        }
        mode_ = mode;
        pix.pixelformat = mode.fourcc;
        pix.width = static_cast<std::uint32_t>(mode.size.width);
        pix.height = static_cast<std::uint32_t>(mode.size.height);
        pix.bytesperline = mode.fourcc == V4L2_PIX_FMT_NV12 || mode.fourcc == V4L2_PIX_FMT_MJPEG
                               ? pix.width
                               : pix.width * 2;
        pix.sizeimage = frameBytes();
        return 0;
      }
      case VIDIOC_G_PARM:
      case VIDIOC_S_PARM: {
        auto* parameters = static_cast<v4l2_streamparm*>(argument);
        parameters->parm.capture.capability = V4L2_CAP_TIMEPERFRAME;
        parameters->parm.capture.timeperframe = {1, 30};
        return 0;
      }
      case VIDIOC_QUERYCTRL: {
        auto* query = static_cast<v4l2_queryctrl*>(argument);
        for (const auto& control : state_->controls) {
          if (control.id == query->id) {
            *query = control;
            return 0;
          }
        }
        return EINVAL;
      }
      case VIDIOC_S_CTRL:
        state_->controlsSet.push_back(*static_cast<v4l2_control*>(argument));
        return 0;
      case VIDIOC_REQBUFS: {
        const auto* wanted = static_cast<v4l2_requestbuffers*>(argument);
        buffers_.assign(wanted->count, std::vector<std::uint8_t>(frameBytes()));
        queue_.clear();
        return 0;
      }
      case VIDIOC_QUERYBUF: {
        auto* buffer = static_cast<v4l2_buffer*>(argument);
        if (buffer->index >= buffers_.size()) return EINVAL;
        buffer->length = static_cast<std::uint32_t>(buffers_[buffer->index].size());
        buffer->m.offset = buffer->index << 16;
        return 0;
      }
      case VIDIOC_EXPBUF: {
        if (!state_->exportsDmabuf) return ENOTTY;
        static_cast<v4l2_exportbuffer*>(argument)->fd = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
        return 0;
      }
      case VIDIOC_QBUF:
        queue_.push_back(static_cast<v4l2_buffer*>(argument)->index);
        return 0;
      case VIDIOC_DQBUF:
        return dequeue(*static_cast<v4l2_buffer*>(argument));
      case VIDIOC_STREAMON:
        streaming_ = true;
        return 0;
      case VIDIOC_STREAMOFF:
        streaming_ = false;
        queue_.clear();
        return 0;
      default:
        return ENOTTY;
    }
  }

 private:
  std::vector<std::uint32_t> distinctFourccs() const {
    std::vector<std::uint32_t> fourccs;
    for (const auto& mode : state_->modes) {
      if (std::ranges::find(fourccs, mode.fourcc) == fourccs.end()) fourccs.push_back(mode.fourcc);
    }
    return fourccs;
  }

  std::uint32_t frameBytes() const {
    const auto pixels = static_cast<std::uint32_t>(mode_.size.area());
    if (mode_.fourcc == V4L2_PIX_FMT_NV12) return pixels * 3 / 2;
    if (mode_.fourcc == V4L2_PIX_FMT_MJPEG) return pixels * 3;  // room for any JPEG of it
    return pixels * 2;
  }

  int dequeue(v4l2_buffer& buffer) {
    if (!streaming_ || queue_.empty()) return EAGAIN;
    const std::uint32_t index = queue_.front();
    queue_.pop_front();
    const std::uint64_t frame = state_->produced++;
    const cv::Mat picture = state_->picture(frame, mode_.size);
    std::vector<std::uint8_t> bytes;
    if (mode_.fourcc == V4L2_PIX_FMT_YUYV || mode_.fourcc == V4L2_PIX_FMT_UYVY) {
      bytes = packedYuv(picture, mode_.fourcc == V4L2_PIX_FMT_YUYV);
    } else if (mode_.fourcc == V4L2_PIX_FMT_NV12) {
      bytes = nv12(picture);
    } else {
      cv::imencode(".jpg", picture, bytes, {cv::IMWRITE_JPEG_QUALITY, 95});
      if (state_->corruptNext) {
        bytes.resize(bytes.size() / 3);  // a frame cut short on the wire
        state_->corruptNext = false;
      }
    }
    std::memcpy(buffers_[index].data(), bytes.data(), bytes.size());
    buffer = {};
    buffer.index = index;
    buffer.bytesused = static_cast<std::uint32_t>(bytes.size());
    buffer.flags = V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC;
    const std::int64_t us =
        state_->firstTimestampUs + static_cast<std::int64_t>(frame) * state_->periodUs;
    buffer.timestamp = {us / 1'000'000, us % 1'000'000};
    return 0;
  }

  std::shared_ptr<State> state_;
  bool open_ = false;
  bool streaming_ = false;
  Mode mode_{};
  std::vector<std::vector<std::uint8_t>> buffers_;
  std::deque<std::uint32_t> queue_;
};

}  // namespace surroundd::testing
