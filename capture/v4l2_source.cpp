#include "capture/v4l2_source.hpp"

#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <span>
#include <thread>

#include <fcntl.h>
#include <fmt/format.h>
#include <linux/videodev2.h>
#include <unistd.h>

namespace surroundd::capture {
namespace {

struct FormatCode {
  V4l2Format format;
  std::uint32_t fourcc;
  PixelLayout layout;
};
constexpr std::array<FormatCode, 4> kFormats{{
    {V4l2Format::kYuyv, V4L2_PIX_FMT_YUYV, PixelLayout::kYuyv},
    {V4l2Format::kUyvy, V4L2_PIX_FMT_UYVY, PixelLayout::kUyvy},
    {V4l2Format::kNv12, V4L2_PIX_FMT_NV12, PixelLayout::kNv12},
    {V4l2Format::kMjpeg, V4L2_PIX_FMT_MJPEG, PixelLayout::kMjpeg},
}};

struct ControlName {
  const char* name;
  std::uint32_t id;
};
constexpr std::array<ControlName, 8> kControls{{
    {"exposure_auto", V4L2_CID_EXPOSURE_AUTO},
    {"exposure_absolute", V4L2_CID_EXPOSURE_ABSOLUTE},
    {"gain", V4L2_CID_GAIN},
    {"white_balance_auto", V4L2_CID_AUTO_WHITE_BALANCE},
    {"white_balance_temperature", V4L2_CID_WHITE_BALANCE_TEMPERATURE},
    {"brightness", V4L2_CID_BRIGHTNESS},
    {"contrast", V4L2_CID_CONTRAST},
    {"saturation", V4L2_CID_SATURATION},
}};

std::string fourccText(std::uint32_t code) {
  std::string text(4, ' ');
  for (int i = 0; i < 4; ++i)
    text[static_cast<std::size_t>(i)] = static_cast<char>((code >> (8 * i)) & 0xff);
  return text;
}

// What the device offers, for the message when the settings cannot be met: "YUYV 640x480,
// 1280x720; MJPG 1920x1080".
struct Offer {
  std::uint32_t fourcc = 0;
  std::vector<cv::Size> sizes;  // discrete sizes
  bool anySize = false;         // stepwise or continuous ranges
  cv::Size smallest, largest;   // of a range
  bool has(cv::Size size) const {
    if (anySize) {
      return size.width >= smallest.width && size.width <= largest.width &&
             size.height >= smallest.height && size.height <= largest.height;
    }
    return std::ranges::find(sizes, size) != sizes.end();
  }
};

std::vector<Offer> offersOf(V4l2Device& device) {
  std::vector<Offer> offers;
  for (std::uint32_t i = 0;; ++i) {
    v4l2_fmtdesc description{};
    description.index = i;
    description.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (device.ioctl(VIDIOC_ENUM_FMT, &description) != 0) break;
    Offer offer;
    offer.fourcc = description.pixelformat;
    for (std::uint32_t k = 0;; ++k) {
      v4l2_frmsizeenum size{};
      size.index = k;
      size.pixel_format = offer.fourcc;
      if (device.ioctl(VIDIOC_ENUM_FRAMESIZES, &size) != 0) break;
      if (size.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
        offer.sizes.emplace_back(static_cast<int>(size.discrete.width),
                                 static_cast<int>(size.discrete.height));
      } else {
        offer.anySize = true;
        offer.smallest = {static_cast<int>(size.stepwise.min_width),
                          static_cast<int>(size.stepwise.min_height)};
        offer.largest = {static_cast<int>(size.stepwise.max_width),
                         static_cast<int>(size.stepwise.max_height)};
        break;
      }
    }
    offers.push_back(std::move(offer));
  }
  return offers;
}

std::string describe(const std::vector<Offer>& offers) {
  std::string text;
  for (const auto& offer : offers) {
    text += fmt::format("{}{}", text.empty() ? "" : "; ", fourccText(offer.fourcc));
    if (offer.anySize) {
      text += fmt::format(" {}x{} to {}x{}", offer.smallest.width, offer.smallest.height,
                          offer.largest.width, offer.largest.height);
    }
    for (std::size_t k = 0; k < offer.sizes.size(); ++k) {
      text +=
          fmt::format("{}{}x{}", k == 0 ? " " : ", ", offer.sizes[k].width, offer.sizes[k].height);
    }
  }
  return text.empty() ? "nothing" : text;
}

std::string errorText(int error) { return std::strerror(error); }  // NOLINT(concurrency-mt-unsafe)

}  // namespace

const char* toString(V4l2Format format) {
  const auto known = std::ranges::find(kFormats, format, &FormatCode::format);
  return known == kFormats.end() ? "auto" : toString(known->layout);
}

V4l2Source::V4l2Source(std::string cameraName, V4l2Settings settings,
                       std::unique_ptr<V4l2Device> device)
    : camera_(std::move(cameraName)), settings_(std::move(settings)), device_(std::move(device)) {
  period_ = std::chrono::duration_cast<Timestamp>(std::chrono::duration<double>(1 / settings_.fps));
  try {
    start();
  } catch (...) {
    stop();
    throw;
  }
}

V4l2Source::~V4l2Source() { stop(); }

std::string V4l2Source::where() const {
  return fmt::format("camera '{}': {}", camera_, settings_.device.string());
}

void V4l2Source::start() {
  if (const int error = device_->open(settings_.device.string()); error != 0) {
    throw CaptureError(fmt::format("{}: cannot open: {}", where(), errorText(error)));
  }
  v4l2_capability capability{};
  if (const int error = device_->ioctl(VIDIOC_QUERYCAP, &capability); error != 0) {
    throw CaptureError(fmt::format("{}: not a V4L2 device ({})", where(), errorText(error)));
  }
  const std::uint32_t caps = (capability.capabilities & V4L2_CAP_DEVICE_CAPS) != 0
                                 ? capability.device_caps
                                 : capability.capabilities;
  if ((caps & V4L2_CAP_VIDEO_CAPTURE) == 0 || (caps & V4L2_CAP_STREAMING) == 0) {
    throw CaptureError(fmt::format("{} ('{}', driver {}): cannot capture video by streaming",
                                   where(), reinterpret_cast<const char*>(capability.card),
                                   reinterpret_cast<const char*>(capability.driver)));
  }

  // The first wanted format that the device offers at the wanted size.
  const std::vector<Offer> offers = offersOf(*device_);
  const FormatCode* chosen = nullptr;
  for (const auto& candidate : kFormats) {
    if (settings_.format != V4l2Format::kAuto && settings_.format != candidate.format) continue;
    const auto offer = std::ranges::find(offers, candidate.fourcc, &Offer::fourcc);
    if (offer != offers.end() && offer->has(settings_.size)) {
      chosen = &candidate;
      break;
    }
  }
  const auto cannot = [&] {
    return CaptureError(fmt::format("{}: does not offer {} {}x{} (it offers: {})", where(),
                                    toString(settings_.format), settings_.size.width,
                                    settings_.size.height, describe(offers)));
  };
  if (chosen == nullptr) throw cannot();
  v4l2_format format{};
  format.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  format.fmt.pix.width = static_cast<std::uint32_t>(settings_.size.width);
  format.fmt.pix.height = static_cast<std::uint32_t>(settings_.size.height);
  format.fmt.pix.pixelformat = chosen->fourcc;
  format.fmt.pix.field = V4L2_FIELD_NONE;
  if (device_->ioctl(VIDIOC_S_FMT, &format) != 0 || format.fmt.pix.pixelformat != chosen->fourcc ||
      static_cast<int>(format.fmt.pix.width) != settings_.size.width ||
      static_cast<int>(format.fmt.pix.height) != settings_.size.height) {
    throw cannot();
  }
  format_ = chosen->format;
  layout_ = chosen->layout;
  bytesPerLine_ = format.fmt.pix.bytesperline;

  // The frame rate, where the driver lets it be set; the nominal period is what it answers.
  v4l2_streamparm parameters{};
  parameters.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (device_->ioctl(VIDIOC_G_PARM, &parameters) == 0 &&
      (parameters.parm.capture.capability & V4L2_CAP_TIMEPERFRAME) != 0) {
    parameters.parm.capture.timeperframe = {
        1000, static_cast<std::uint32_t>(std::lround(settings_.fps * 1000))};
    if (device_->ioctl(VIDIOC_S_PARM, &parameters) == 0 &&
        parameters.parm.capture.timeperframe.denominator != 0) {
      const auto& t = parameters.parm.capture.timeperframe;
      period_ = Timestamp(static_cast<std::int64_t>(1e9 * t.numerator / t.denominator));
    }
  }

  for (const auto& control : settings_.controls) {
    const auto known = std::ranges::find_if(
        kControls, [&](const ControlName& c) { return control.name == c.name; });
    if (known == kControls.end()) {
      throw CaptureError(fmt::format("{}: unknown control '{}'", where(), control.name));
    }
    v4l2_queryctrl query{};
    query.id = known->id;
    if (device_->ioctl(VIDIOC_QUERYCTRL, &query) != 0 ||
        (query.flags & V4L2_CTRL_FLAG_DISABLED) != 0) {
      throw CaptureError(fmt::format("{}: has no control '{}'", where(), control.name));
    }
    if (control.value < query.minimum || control.value > query.maximum) {
      throw CaptureError(fmt::format("{}: control '{}' takes {} to {}, got {}", where(),
                                     control.name, query.minimum, query.maximum, control.value));
    }
    v4l2_control set{known->id, control.value};
    if (const int error = device_->ioctl(VIDIOC_S_CTRL, &set); error != 0) {
      throw CaptureError(fmt::format("{}: setting control '{}' to {} failed: {}", where(),
                                     control.name, control.value, errorText(error)));
    }
  }

  v4l2_requestbuffers request{};
  request.count = static_cast<std::uint32_t>(settings_.buffers);
  request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  request.memory = V4L2_MEMORY_MMAP;
  if (const int error = device_->ioctl(VIDIOC_REQBUFS, &request); error != 0 || request.count < 2) {
    throw CaptureError(fmt::format("{}: cannot get {} streaming buffers: {}", where(),
                                   settings_.buffers,
                                   error != 0 ? errorText(error) : "too few granted"));
  }
  for (std::uint32_t i = 0; i < request.count; ++i) {
    v4l2_buffer buffer{};
    buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buffer.memory = V4L2_MEMORY_MMAP;
    buffer.index = i;
    if (const int error = device_->ioctl(VIDIOC_QUERYBUF, &buffer); error != 0) {
      throw CaptureError(fmt::format("{}: buffer {}: {}", where(), i, errorText(error)));
    }
    void* address = device_->map(buffer.length, buffer.m.offset);
    if (address == nullptr) throw CaptureError(fmt::format("{}: cannot map buffer {}", where(), i));
    buffers_.push_back({address, buffer.length});
    v4l2_exportbuffer exported{};
    exported.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    exported.index = i;
    exported.flags = O_CLOEXEC | O_RDONLY;
    if (device_->ioctl(VIDIOC_EXPBUF, &exported) == 0) dmabufs_.push_back(exported.fd);
    if (const int error = device_->ioctl(VIDIOC_QBUF, &buffer); error != 0) {
      throw CaptureError(fmt::format("{}: queueing buffer {}: {}", where(), i, errorText(error)));
    }
  }
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (const int error = device_->ioctl(VIDIOC_STREAMON, &type); error != 0) {
    throw CaptureError(fmt::format("{}: cannot start streaming: {}", where(), errorText(error)));
  }
  streaming_ = true;
}

void V4l2Source::stop() {
  if (streaming_) {
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    device_->ioctl(VIDIOC_STREAMOFF, &type);
    streaming_ = false;
  }
  for (const int fd : dmabufs_) ::close(fd);
  dmabufs_.clear();
  for (const auto& buffer : buffers_) device_->unmap(buffer.address, buffer.length);
  if (!buffers_.empty()) {
    v4l2_requestbuffers release{};
    release.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    release.memory = V4L2_MEMORY_MMAP;
    device_->ioctl(VIDIOC_REQBUFS, &release);
  }
  buffers_.clear();
  device_->close();
}

ReadStatus V4l2Source::fault(std::string message, bool reopen) {
  error_ = std::move(message);
  if (reopen) {
    stop();
    backoff_ = backoff_.count() == 0 ? settings_.firstBackoff
                                     : std::min(backoff_ * 2, settings_.maxBackoff);
    nextAttempt_ = std::chrono::steady_clock::now() + backoff_;
  }
  return ReadStatus::kFault;
}

ReadStatus V4l2Source::reopen() {
  std::this_thread::sleep_until(nextAttempt_);
  try {
    start();
  } catch (const CaptureError& e) {
    return fault(fmt::format("reopening failed (next try in {} ms): {}",
                             std::min(backoff_ * 2, settings_.maxBackoff).count(), e.what()),
                 true);
  }
  ++reopened_;
  backoff_ = std::chrono::milliseconds(0);
  return ReadStatus::kFrame;
}

ReadStatus V4l2Source::read(Frame& out) {
  if (!streaming_ && reopen() != ReadStatus::kFrame) return ReadStatus::kFault;
  if (const int error = device_->waitReadable(settings_.timeout); error != 0) {
    if (error == ETIMEDOUT) {
      return fault(
          fmt::format("{}: no frame within {} ms; reopening", where(), settings_.timeout.count()),
          true);
    }
    return fault(fmt::format("{}: {}; reopening", where(), errorText(error)), true);
  }
  v4l2_buffer buffer{};
  buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  buffer.memory = V4L2_MEMORY_MMAP;
  if (const int error = device_->ioctl(VIDIOC_DQBUF, &buffer); error != 0) {
    if (error == EAGAIN) return fault(fmt::format("{}: woke without a frame", where()), false);
    return fault(fmt::format("{}: {}; reopening", where(), errorText(error)), true);
  }
  bool good = (buffer.flags & V4L2_BUF_FLAG_ERROR) == 0 && buffer.index < buffers_.size();
  std::string problem = good ? "" : "the driver marked the frame corrupt";
  if (good) {
    good = convert(static_cast<const std::uint8_t*>(buffers_[buffer.index].address),
                   buffer.bytesused, out.image);
    if (!good) problem = error_;
  }
  out.timestamp = std::chrono::seconds(buffer.timestamp.tv_sec) +
                  std::chrono::microseconds(buffer.timestamp.tv_usec);
  if (const int error = device_->ioctl(VIDIOC_QBUF, &buffer); error != 0) {
    return fault(fmt::format("{}: requeueing a buffer: {}; reopening", where(), errorText(error)),
                 true);
  }
  if (!good) return fault(fmt::format("{}: {}", where(), problem), false);
  return ReadStatus::kFrame;
}

bool V4l2Source::convert(const std::uint8_t* data, std::size_t bytes, cv::Mat& bgr) {
  return convertToBgr(layout_, std::span(data, bytes), bytesPerLine_, jpeg_, bgr, error_);
}

}  // namespace surroundd::capture
