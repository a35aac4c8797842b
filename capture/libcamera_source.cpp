#include "capture/libcamera_source.hpp"

#include <algorithm>
#include <condition_variable>
#include <cstdlib>
#include <deque>
#include <map>
#include <mutex>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <libcamera/libcamera.h>
#include <sys/mman.h>

#include "capture/pixel_conversion.hpp"

namespace surroundd::capture {
namespace {

// libcamera allows one camera manager per process: the cameras share it while any is open.
std::shared_ptr<libcamera::CameraManager> sharedManager() {
  static std::mutex mutex;
  static std::weak_ptr<libcamera::CameraManager> shared;
  const std::lock_guard lock(mutex);
  if (auto manager = shared.lock()) return manager;
  // libcamera logs at INFO to stderr by default; keep its warnings unless its own variable says.
  // NOLINTNEXTLINE(concurrency-mt-unsafe): read under the mutex, before libcamera starts threads.
  if (std::getenv("LIBCAMERA_LOG_LEVELS") == nullptr) libcamera::logSetLevel("*", "WARN");
  std::shared_ptr<libcamera::CameraManager> manager(new libcamera::CameraManager,
                                                    [](libcamera::CameraManager* m) {
                                                      m->stop();
                                                      delete m;
                                                    });
  if (const int error = manager->start(); error != 0) {
    throw CaptureError(fmt::format("libcamera: the camera manager does not start ({})", error));
  }
  shared = manager;
  return manager;
}

struct Candidate {
  libcamera::PixelFormat format;
  PixelLayout layout = PixelLayout::kBgr;
};

}  // namespace

bool libcameraAvailable() { return true; }

std::vector<std::string> libcameraCameras() {
  const auto manager = sharedManager();
  std::vector<std::string> lines;
  for (const auto& camera : manager->cameras()) {
    std::string line = camera->id();
    if (const auto model = camera->properties().get(libcamera::properties::Model)) {
      line += fmt::format(" ({})", *model);
    }
    const auto configuration = camera->generateConfiguration({libcamera::StreamRole::Viewfinder});
    if (configuration && !configuration->empty()) {
      const libcamera::StreamFormats& formats = configuration->at(0).formats();
      std::vector<std::string> offers;
      for (const auto& format : formats.pixelformats()) {
        const auto range = formats.range(format);
        offers.push_back(fmt::format("{} {} to {}", format.toString(), range.min.toString(),
                                     range.max.toString()));
      }
      line += fmt::format(": {}", fmt::join(offers, "; "));
    }
    lines.push_back(std::move(line));
  }
  return lines;
}

struct LibcameraSource::Impl {
  std::string name;
  LibcameraSettings settings;
  std::shared_ptr<libcamera::CameraManager> manager;
  std::shared_ptr<libcamera::Camera> camera;
  std::unique_ptr<libcamera::CameraConfiguration> configuration;
  libcamera::Stream* stream = nullptr;
  std::unique_ptr<libcamera::FrameBufferAllocator> allocator;
  std::vector<std::unique_ptr<libcamera::Request>> requests;
  struct Mapping {
    void* address = nullptr;
    std::size_t length = 0;
    std::size_t offset = 0;  // of plane 0 in the mapping
  };
  std::map<const libcamera::FrameBuffer*, Mapping> mappings;
  PixelLayout layout = PixelLayout::kBgr;
  std::size_t stride = 0;
  JpegDecoder jpeg;
  bool acquired = false;
  bool started = false;
  std::string error;

  // Completed requests, handed from libcamera's thread to the capture thread.
  std::mutex mutex;
  std::condition_variable ready;
  std::deque<libcamera::Request*> completed;

  void onRequestCompleted(libcamera::Request* request) {
    if (request->status() == libcamera::Request::RequestCancelled) return;
    {
      const std::lock_guard lock(mutex);
      completed.push_back(request);
    }
    ready.notify_one();
  }

  std::string where() const {
    return fmt::format("camera '{}': libcamera {}", name, camera ? camera->id() : settings.camera);
  }

  void open();
  void close();
};

void LibcameraSource::Impl::open() {
  manager = sharedManager();
  std::string found;
  for (const auto& candidate : manager->cameras()) {
    found += (found.empty() ? "" : ", ") + candidate->id();
    if (!camera && candidate->id().find(settings.camera) != std::string::npos) camera = candidate;
  }
  if (!camera) {
    throw CaptureError(fmt::format("camera '{}': no libcamera camera matches '{}' (found: {})",
                                   name, settings.camera, found.empty() ? "none" : found));
  }
  if (camera->acquire() != 0) throw CaptureError(where() + ": busy (another process has it)");
  acquired = true;
  configuration = camera->generateConfiguration({libcamera::StreamRole::VideoRecording});
  if (!configuration || configuration->empty()) {
    throw CaptureError(where() + ": has no video stream");
  }
  libcamera::StreamConfiguration& config = configuration->at(0);
  const libcamera::Size wanted(static_cast<unsigned>(settings.size.width),
                               static_cast<unsigned>(settings.size.height));
  // RGB888 is libcamera's name for bytes in the order B, G, R.
  const std::array<Candidate, 4> candidates{{{libcamera::formats::RGB888, PixelLayout::kBgr},
                                             {libcamera::formats::YUYV, PixelLayout::kYuyv},
                                             {libcamera::formats::UYVY, PixelLayout::kUyvy},
                                             {libcamera::formats::NV12, PixelLayout::kNv12}}};
  bool chosen = false;
  for (const auto& candidate : candidates) {
    config.pixelFormat = candidate.format;
    config.size = wanted;
    config.bufferCount = static_cast<unsigned>(settings.buffers);
    if (configuration->validate() != libcamera::CameraConfiguration::Invalid &&
        config.pixelFormat == candidate.format && config.size == wanted) {
      layout = candidate.layout;
      chosen = true;
      break;
    }
  }
  if (!chosen) {
    std::string offers;
    for (const auto& format : config.formats().pixelformats()) {
      offers += (offers.empty() ? "" : ", ") + format.toString();
    }
    throw CaptureError(fmt::format("{}: cannot give BGR, YUYV, UYVY or NV12 at {}x{} (formats: {})",
                                   where(), settings.size.width, settings.size.height, offers));
  }
  stride = config.stride;
  if (camera->configure(configuration.get()) != 0) {
    throw CaptureError(where() + ": refuses its configuration");
  }
  stream = config.stream();
  allocator = std::make_unique<libcamera::FrameBufferAllocator>(camera);
  if (allocator->allocate(stream) < 0) throw CaptureError(where() + ": cannot allocate buffers");
  for (const auto& buffer : allocator->buffers(stream)) {
    // The planes share one dmabuf in the pipelines that matter; map it once, whole.
    const auto& planes = buffer->planes();
    std::size_t length = 0;
    for (const auto& plane : planes)
      length = std::max<std::size_t>(length, plane.offset + plane.length);
    void* address = ::mmap(nullptr, length, PROT_READ, MAP_SHARED, planes.front().fd.get(), 0);
    if (address == MAP_FAILED) throw CaptureError(where() + ": cannot map a buffer");
    mappings[buffer.get()] = {address, length, planes.front().offset};
    std::unique_ptr<libcamera::Request> request = camera->createRequest();
    if (!request || request->addBuffer(stream, buffer.get()) != 0) {
      throw CaptureError(where() + ": cannot make a request");
    }
    requests.push_back(std::move(request));
  }
  camera->requestCompleted.connect(this, &Impl::onRequestCompleted);
  if (camera->start() != 0) throw CaptureError(where() + ": does not start");
  started = true;
  for (const auto& request : requests) camera->queueRequest(request.get());
}

void LibcameraSource::Impl::close() {
  if (started) camera->stop();
  started = false;
  if (camera) camera->requestCompleted.disconnect(this);
  requests.clear();
  for (const auto& [buffer, mapping] : mappings) ::munmap(mapping.address, mapping.length);
  mappings.clear();
  if (allocator && stream != nullptr) allocator->free(stream);
  allocator.reset();
  if (acquired) camera->release();
  acquired = false;
  camera.reset();
}

LibcameraSource::LibcameraSource(std::string cameraName, LibcameraSettings settings)
    : impl_(std::make_unique<Impl>()) {
  impl_->name = std::move(cameraName);
  impl_->settings = std::move(settings);
  try {
    impl_->open();
  } catch (...) {
    impl_->close();
    throw;
  }
}

LibcameraSource::~LibcameraSource() { impl_->close(); }

cv::Size LibcameraSource::frameSize() const { return impl_->settings.size; }

PixelFormat LibcameraSource::pixelFormat() const { return heldFormat(impl_->layout); }

Timestamp LibcameraSource::nominalPeriod() const {
  return std::chrono::duration_cast<Timestamp>(
      std::chrono::duration<double>(1 / impl_->settings.fps));
}

const std::string& LibcameraSource::lastError() const { return impl_->error; }

void LibcameraSource::reopen() {
  impl_->close();
  {
    const std::lock_guard lock(impl_->mutex);
    impl_->completed.clear();
  }
  try {
    impl_->open();
  } catch (...) {
    impl_->close();
    throw;
  }
}

ReadStatus LibcameraSource::read(Frame& out) {
  Impl& s = *impl_;
  if (!s.started) {
    s.error = fmt::format("{}: stopped; reopen it", s.where());
    return ReadStatus::kLost;
  }
  libcamera::Request* request = nullptr;
  {
    std::unique_lock lock(s.mutex);
    if (!s.ready.wait_for(lock, s.settings.timeout, [&] { return !s.completed.empty(); })) {
      s.error = fmt::format("{}: no frame within {} ms; reopening", s.where(),
                            s.settings.timeout.count());
      lock.unlock();
      s.close();
      return ReadStatus::kLost;
    }
    request = s.completed.front();
    s.completed.pop_front();
  }
  const libcamera::FrameBuffer* buffer = request->buffers().begin()->second;
  const libcamera::FrameMetadata& metadata = buffer->metadata();
  bool good = request->status() == libcamera::Request::RequestComplete &&
              metadata.status == libcamera::FrameMetadata::FrameSuccess;
  if (!good) s.error = fmt::format("{}: a request failed", s.where());
  if (good) {
    const Impl::Mapping& mapping = s.mappings.at(buffer);
    std::size_t bytes = 0;
    for (const auto& plane : metadata.planes()) bytes += plane.bytesused;
    const auto* data = static_cast<const std::uint8_t*>(mapping.address) + mapping.offset;
    good = holdFrame(s.layout, std::span(data, std::min(bytes, mapping.length - mapping.offset)),
                     s.stride, s.jpeg, s.settings.size, out.image, s.error);
    out.timestamp = Timestamp(static_cast<std::int64_t>(metadata.timestamp));
  }
  request->reuse(libcamera::Request::ReuseBuffers);
  if (s.camera->queueRequest(request) != 0) {
    s.error = fmt::format("{}: cannot requeue a request", s.where());
    return ReadStatus::kFault;
  }
  return good ? ReadStatus::kFrame : ReadStatus::kFault;
}

}  // namespace surroundd::capture
