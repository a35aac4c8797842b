#include "capture/v4l2_source.hpp"

#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <span>

#include <fcntl.h>
#include <fmt/format.h>
#include <linux/videodev2.h>
#include <unistd.h>

#include "capture/v4l2_formats.hpp"
#include "capture/v4l2_probe.hpp"

namespace surroundd::capture {
namespace {

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

std::string errorText(int error) { return std::strerror(error); }  // NOLINT(concurrency-mt-unsafe)

}  // namespace

const char* toString(V4l2Format format) {
  const auto known = std::ranges::find(kV4l2Formats, format, &V4l2FormatCode::format);
  return known == kV4l2Formats.end() ? "auto" : toString(known->layout);
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
  const V4l2Probe probe = probeV4l2(*device_, where());
  if (!probe.capture) {
    throw CaptureError(fmt::format("{} ('{}', driver {}): cannot capture video by streaming",
                                   where(), probe.card, probe.driver));
  }
  multiplanar_ = probe.multiplanar;
  bufferType_ = probe.bufferType;
  const V4l2FormatCode* chosen = chooseV4l2Format(probe, settings_);
  const auto cannot = [&] {
    return CaptureError(fmt::format("{}: {}", where(), notOffered(probe, settings_)));
  };
  if (chosen == nullptr) throw cannot();
  setFormat(*chosen, cannot);

  // The frame rate, where the driver lets it be set; the nominal period is what it answers.
  v4l2_streamparm parameters{};
  parameters.type = bufferType_;
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

  mapBuffers();
  if (const int error = buffers_->startStreaming(); error != 0) {
    throw CaptureError(fmt::format("{}: cannot start streaming: {}", where(), errorText(error)));
  }
  streaming_ = true;
}

void V4l2Source::setFormat(const V4l2FormatCode& chosen,
                           const std::function<CaptureError()>& cannot) {
  v4l2_format format{};
  format.type = bufferType_;
  const auto width = static_cast<std::uint32_t>(settings_.size.width);
  const auto height = static_cast<std::uint32_t>(settings_.size.height);
  bytesPerLine_.clear();
  if (multiplanar_) {
    auto& pix = format.fmt.pix_mp;
    pix.width = width;
    pix.height = height;
    pix.pixelformat = chosen.fourcc;
    pix.field = V4L2_FIELD_NONE;
    pix.num_planes = static_cast<std::uint8_t>(chosen.planes);
    if (device_->ioctl(VIDIOC_S_FMT, &format) != 0 || pix.pixelformat != chosen.fourcc ||
        pix.width != width || pix.height != height) {
      throw cannot();
    }
    if (pix.num_planes != chosen.planes) {
      throw CaptureError(fmt::format("{}: {} comes in {} planes, expected {}", where(),
                                     fourccText(chosen.fourcc), pix.num_planes, chosen.planes));
    }
    for (std::uint32_t p = 0; p < pix.num_planes; ++p) {
      bytesPerLine_.push_back(pix.plane_fmt[p].bytesperline);
    }
  } else {
    auto& pix = format.fmt.pix;
    pix.width = width;
    pix.height = height;
    pix.pixelformat = chosen.fourcc;
    pix.field = V4L2_FIELD_NONE;
    if (device_->ioctl(VIDIOC_S_FMT, &format) != 0 || pix.pixelformat != chosen.fourcc ||
        pix.width != width || pix.height != height) {
      throw cannot();
    }
    bytesPerLine_.push_back(pix.bytesperline);
  }
  format_ = chosen.format;
  layout_ = chosen.layout;
}

void V4l2Source::mapBuffers() {
  v4l2_requestbuffers request{};
  request.count = static_cast<std::uint32_t>(settings_.buffers);
  request.type = bufferType_;
  request.memory = V4L2_MEMORY_MMAP;
  if (const int error = device_->ioctl(VIDIOC_REQBUFS, &request); error != 0 || request.count < 2) {
    throw CaptureError(fmt::format("{}: cannot get {} streaming buffers: {}", where(),
                                   settings_.buffers,
                                   error != 0 ? errorText(error) : "too few granted"));
  }
  requested_ = true;
  orphans_ = (request.capabilities & V4L2_BUF_CAP_SUPPORTS_ORPHANED_BUFS) != 0;
  buffers_ = std::make_shared<V4l2Buffers>(device_, bufferType_, bytesPerLine_.size());
  for (std::uint32_t i = 0; i < request.count; ++i) {
    std::array<v4l2_plane, VIDEO_MAX_PLANES> planes{};
    v4l2_buffer buffer = buffers_->describe(planes);
    buffer.index = i;
    if (const int error = device_->ioctl(VIDIOC_QUERYBUF, &buffer); error != 0) {
      throw CaptureError(fmt::format("{}: buffer {}: {}", where(), i, errorText(error)));
    }
    std::vector<V4l2Buffers::Plane> mapped;
    // Added before anything can throw, so that the buffers unmap and close what is there.
    const auto keep = [&] { buffers_->add(std::move(mapped)); };
    for (std::size_t p = 0; p < bytesPerLine_.size(); ++p) {
      const std::size_t length = multiplanar_ ? planes[p].length : buffer.length;
      const std::int64_t offset = multiplanar_ ? planes[p].m.mem_offset : buffer.m.offset;
      void* address = device_->map(length, offset);
      if (address == nullptr) {
        keep();
        throw CaptureError(fmt::format("{}: cannot map buffer {} plane {}", where(), i, p));
      }
      v4l2_exportbuffer exported{};
      exported.type = bufferType_;
      exported.index = i;
      exported.plane = static_cast<std::uint32_t>(p);
      exported.flags = O_CLOEXEC | O_RDONLY;
      const bool exports = device_->ioctl(VIDIOC_EXPBUF, &exported) == 0;
      mapped.push_back({address, length, exports ? exported.fd : -1});
      if (exports) dmabufs_.push_back(exported.fd);
    }
    keep();
    if (const int error = buffers_->queue(buffer); error != 0) {
      throw CaptureError(fmt::format("{}: queueing buffer {}: {}", where(), i, errorText(error)));
    }
  }
}

void V4l2Source::stop() {
  if (buffers_) {
    buffers_->stopStreaming();
    buffers_.reset();  // unmapped here, or once the last frame lent a buffer returns
  }
  streaming_ = false;
  dmabufs_.clear();
  if (requested_) {
    // With buffers still lent the kernel keeps them (orphaned) until they are unmapped.
    v4l2_requestbuffers release{};
    release.type = bufferType_;
    release.memory = V4L2_MEMORY_MMAP;
    device_->ioctl(VIDIOC_REQBUFS, &release);
    requested_ = false;
  }
  device_->close();
}

const char* V4l2Source::lendBuffers() {
  const char* refusal = lendingRefusal();
  lend_ = refusal == nullptr;
  return refusal;
}

const char* V4l2Source::lendingRefusal() const {
  if (layout_ != PixelLayout::kYuyv && layout_ != PixelLayout::kUyvy &&
      layout_ != PixelLayout::kNv12) {
    return "its frames are converted to BGR";
  }
  if (bytesPerLine_.size() > 1) return "its NV12 comes in two buffers, which no picture can view";
  if (dmabufs_.empty()) return "its driver exports no DMABUF";
  if (dmabufs_.size() < buffers_->count()) return "its driver exported only some of its buffers";
  // This one and two more, since two always stay with the driver (V4l2Buffers::lend).
  if (buffers_->count() < 3) return "it has fewer than three buffers (capture.buffers)";
  // Without, a camera lost while a frame holds a buffer could not be opened again until the frame
  // let go of it (REQBUFS would be refused).
  if (!orphans_) return "its driver cannot free buffers that a frame still holds";
  const cv::Size held = heldSize(heldFormat(layout_), settings_.size);
  if (bytesPerLine_[0] !=
      static_cast<std::size_t>(held.width) * CV_ELEM_SIZE(heldType(heldFormat(layout_)))) {
    return "its lines are padded";
  }
  return nullptr;
}

ReadStatus V4l2Source::fault(std::string message, bool lost) {
  error_ = std::move(message);
  if (!lost) return ReadStatus::kFault;
  stop();
  return ReadStatus::kLost;
}

void V4l2Source::reopen() {
  const PixelFormat held = pixelFormat();
  stop();
  try {
    start();
    // The frames already allocated hold the first format; a device that now offers another
    // (format: auto) cannot fill them.
    if (pixelFormat() != held) {
      throw CaptureError(fmt::format("{}: reopened in {}, but its frames are held as {}", where(),
                                     toString(layout_), toString(held)));
    }
  } catch (...) {
    stop();
    throw;
  }
  ++reopened_;
}

ReadStatus V4l2Source::read(Frame& out) {
  endLoan(out);
  if (!streaming_) return fault(fmt::format("{}: closed; reopen it", where()), true);
  if (const int error = buffers_->requeueError(); error != 0) {
    return fault(fmt::format("{}: requeueing a buffer: {}; reopening", where(), errorText(error)),
                 true);
  }
  if (const int error = device_->waitReadable(settings_.timeout); error != 0) {
    if (error == ETIMEDOUT) {
      return fault(
          fmt::format("{}: no frame within {} ms; reopening", where(), settings_.timeout.count()),
          true);
    }
    return fault(fmt::format("{}: {}; reopening", where(), errorText(error)), true);
  }
  std::array<v4l2_plane, VIDEO_MAX_PLANES> planes{};
  v4l2_buffer buffer = buffers_->describe(planes);
  if (const int error = buffers_->dequeue(buffer); error != 0) {
    if (error == EAGAIN) return fault(fmt::format("{}: woke without a frame", where()), false);
    return fault(fmt::format("{}: {}; reopening", where(), errorText(error)), true);
  }
  out.timestamp = std::chrono::seconds(buffer.timestamp.tv_sec) +
                  std::chrono::microseconds(buffer.timestamp.tv_usec);
  bool good = (buffer.flags & V4L2_BUF_FLAG_ERROR) == 0 && buffer.index < buffers_->count();
  std::string problem = good ? "" : "the driver marked the frame corrupt";
  if (good && lend_ && lendingRefusal() == nullptr && lend(buffer, out)) return ReadStatus::kFrame;
  if (good) {
    good = hold(buffer, out.image);
    if (!good) problem = error_;
  }
  if (const int error = buffers_->queue(buffer); error != 0) {
    return fault(fmt::format("{}: requeueing a buffer: {}; reopening", where(), errorText(error)),
                 true);
  }
  if (!good) return fault(fmt::format("{}: {}", where(), problem), false);
  return ReadStatus::kFrame;
}

bool V4l2Source::filled(const v4l2_buffer& buffer,
                        std::array<std::span<const std::uint8_t>, 2>& data) {
  const std::span<const V4l2Buffers::Plane> mapped = buffers_->planes(buffer.index);
  for (std::size_t p = 0; p < mapped.size() && p < data.size(); ++p) {
    const std::size_t used = multiplanar_ ? buffer.m.planes[p].bytesused : buffer.bytesused;
    const std::size_t offset = multiplanar_ ? buffer.m.planes[p].data_offset : 0;
    const std::size_t end = std::min(used, mapped[p].length);
    if (offset > end) {
      error_ = fmt::format("plane {} starts at {}, past its {} bytes", p, offset, end);
      return false;
    }
    data[p] = std::span(static_cast<const std::uint8_t*>(mapped[p].address) + offset, end - offset);
  }
  return true;
}

bool V4l2Source::hold(const v4l2_buffer& buffer, cv::Mat& held) {
  std::array<std::span<const std::uint8_t>, 2> data;
  if (!filled(buffer, data)) return false;
  if (buffers_->planes(buffer.index).size() == 2) {
    return holdNv12Planes({data[0], bytesPerLine_[0]}, {data[1], bytesPerLine_[1]}, settings_.size,
                          held, error_);
  }
  return holdFrame(layout_, data[0], bytesPerLine_[0], jpeg_, settings_.size, held, error_);
}

// One plane whose lines are unpadded (lendingRefusal()), viewed as it is: false (to be held as a
// copy, or found short there) when the driver filled less than a picture or no buffer can be lent.
bool V4l2Source::lend(const v4l2_buffer& buffer, Frame& out) {
  std::array<std::span<const std::uint8_t>, 2> data;
  const PixelFormat format = heldFormat(layout_);
  const cv::Size size = heldSize(format, settings_.size);
  const auto bytes = static_cast<std::size_t>(size.area()) * CV_ELEM_SIZE(heldType(format));
  if (!filled(buffer, data) || data[0].size() < bytes || !buffers_->lend(buffer.index)) {
    return false;
  }
  const V4l2Buffers::Plane& plane = buffers_->planes(buffer.index)[0];
  const auto offset =
      static_cast<std::uint32_t>(data[0].data() - static_cast<const std::uint8_t*>(plane.address));
  const auto pitch = static_cast<std::uint32_t>(bytesPerLine_[0]);
  out.loan.own = out.image;
  out.loan.lender = buffers_;
  out.loan.buffer = buffer.index;
  // cv::Mat takes a writable pointer; nothing down the pipeline writes a frame's picture.
  out.image = cv::Mat(size, heldType(format), const_cast<std::uint8_t*>(data[0].data()));
  out.dmabuf.fd = {plane.dmabuf, plane.dmabuf};
  out.dmabuf.pitch = {pitch, pitch};
  out.dmabuf.offset = {offset, offset + pitch * static_cast<std::uint32_t>(settings_.size.height)};
  out.dmabuf.planes = format == PixelFormat::kNv12 ? 2 : 1;
  out.dmabuf.session = buffers_->session();
  out.dmabuf.index = buffer.index;
  return true;
}

}  // namespace surroundd::capture
