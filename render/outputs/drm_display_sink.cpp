#include "render/outputs/drm_display_sink.hpp"

#include <algorithm>
#include <array>

#include <fmt/format.h>
#include <gbm.h>
#include <opencv2/imgproc.hpp>

#include "render/render_error.hpp"

namespace surroundd::render {

struct DrmDisplaySink::Buffers {
  struct Buffer {
    gbm_bo* bo = nullptr;
    void* mapping = nullptr;
    cv::Mat pixels;  // BGRX over the mapping
  };

  Buffers(gbm_device* gbm, cv::Size size, const std::filesystem::path& card) {
    for (auto& buffer : buffers) {
      buffer.bo = gbm_bo_create(gbm, size.width, size.height, GBM_FORMAT_XRGB8888,
                                GBM_BO_USE_SCANOUT | GBM_BO_USE_LINEAR);
      if (buffer.bo == nullptr) {
        throw RenderError(fmt::format("display {}: cannot allocate a {}x{} scan-out buffer",
                                      card.string(), size.width, size.height));
      }
      // Mapped once for the sink's life: writing a frame is then a plain memory copy.
      std::uint32_t stride = 0;
      void* data = gbm_bo_map(buffer.bo, 0, 0, size.width, size.height, GBM_BO_TRANSFER_WRITE,
                              &stride, &buffer.mapping);
      if (data == nullptr) {
        throw RenderError(fmt::format("display {}: cannot map a scan-out buffer", card.string()));
      }
      buffer.pixels = cv::Mat(size, CV_8UC4, data, stride);
      buffer.pixels.setTo(cv::Scalar::all(0));
    }
  }
  ~Buffers() {
    for (auto& buffer : buffers) {
      if (buffer.mapping != nullptr) gbm_bo_unmap(buffer.bo, buffer.mapping);
      if (buffer.bo != nullptr) gbm_bo_destroy(buffer.bo);
    }
  }
  Buffers(const Buffers&) = delete;
  Buffers& operator=(const Buffers&) = delete;

  std::array<Buffer, 2> buffers;
  std::size_t back = 1;  // the first is shown black when the mode is set
  cv::Mat scaled;        // a picture scaled to the mode, before it is widened into the back buffer
};

DrmDisplaySink::DrmDisplaySink(const DrmDisplaySettings& settings)
    : card_(settings),
      screen_(card_.fd(), card_.path(), settings.connector),
      buffers_(std::make_unique<Buffers>(card_.gbm(), screen_.size(), card_.path())) {
  screen_.show(screen_.framebufferOf(buffers_->buffers[0].bo));
}

DrmDisplaySink::~DrmDisplaySink() = default;

void DrmDisplaySink::consume(const cv::Mat& bgr, const PictureTime& /*time*/) {
  if (bgr.type() != CV_8UC3) {
    throw RenderError(
        fmt::format("display {}: expected an 8-bit BGR picture", card_.path().string()));
  }
  // The back buffer is free once the previous flip has shown the other one.
  screen_.finishFlip();
  auto& buffer = buffers_->buffers[buffers_->back];
  const cv::Size target = buffer.pixels.size();
  const double scale = std::min(static_cast<double>(target.width) / bgr.cols,
                                static_cast<double>(target.height) / bgr.rows);
  const cv::Size fitted(static_cast<int>(bgr.cols * scale), static_cast<int>(bgr.rows * scale));
  const cv::Rect area((target.width - fitted.width) / 2, (target.height - fitted.height) / 2,
                      fitted.width, fitted.height);
  cv::Mat region = buffer.pixels(area);  // written in place: cvtColor keeps its size and type
  if (fitted == bgr.size()) {
    cv::cvtColor(bgr, region, cv::COLOR_BGR2BGRA);
  } else {
    cv::resize(bgr, buffers_->scaled, fitted, 0, 0, cv::INTER_LINEAR);  // allocated once
    cv::cvtColor(buffers_->scaled, region, cv::COLOR_BGR2BGRA);
  }
  screen_.show(screen_.framebufferOf(buffer.bo));
  buffers_->back = 1 - buffers_->back;
  ++frames_;
}

void DrmDisplaySink::finish(const cv::Mat& /*lastFrame*/, std::chrono::nanoseconds /*lastTime*/) {
  screen_.finishFlip();
}

std::string DrmDisplaySink::describe() const {
  return fmt::format("display {} ({} frames)", screen_.describe(), frames_);
}

}  // namespace surroundd::render
