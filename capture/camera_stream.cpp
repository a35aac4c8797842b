#include "capture/camera_stream.hpp"

#include <spdlog/spdlog.h>

namespace surroundd::capture {
namespace {

// How long the capture thread waits for a free buffer before it checks whether it should stop.
constexpr std::chrono::milliseconds kPoolWait{100};

}  // namespace

CameraStream::CameraStream(std::string name, std::unique_ptr<FrameSource> source,
                           std::size_t poolFrames, RecoverySettings recovery)
    : name_(std::move(name)),
      source_(std::move(source)),
      pool_(poolFrames, source_->frameSize(), source_->pixelFormat()),
      nominalPeriod_(source_->nominalPeriod()),
      repeatsOnePicture_(source_->repeatsOnePicture()),
      recovery_(recovery),
      queue_(poolFrames) {}

CameraStream::~CameraStream() { stop(); }

void CameraStream::start() {
  thread_ = std::thread([this] { run(); });
}

void CameraStream::stop() {
  {
    const std::lock_guard lock(stopMutex_);
    stopping_ = true;
  }
  stopCondition_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void CameraStream::run() {
  SourceRecovery recovery(name_, recovery_);
  const SourceRecovery::Wait wait = [this](std::chrono::milliseconds duration) {
    std::unique_lock lock(stopMutex_);
    return !stopCondition_.wait_for(lock, duration, [this] { return stopping_.load(); });
  };
  std::uint64_t sequence = 0;
  while (!stopping_) {
    FrameRef frame = pool_.acquire(kPoolWait);
    if (!frame) continue;
    const auto readStart = std::chrono::steady_clock::now();
    const ReadStatus status = recovery.read(*source_, *frame, wait);
    {
      const std::lock_guard lock(mutex_);
      stats_.faults = recovery.faults();
      stats_.reopens = recovery.reopens();
    }
    if (status == ReadStatus::kFrame) {
      frame->sequence = sequence++;
      push(std::move(frame), std::chrono::steady_clock::now() - readStart);
      continue;
    }
    if (status == ReadStatus::kFault) continue;
    if (!recovery.gaveUp() && !stopping_) {
      spdlog::info("camera '{}': end of stream after {} frames", name_, sequence);
    }
    break;
  }
  recovery.onEnd(std::chrono::steady_clock::now());
  {
    const std::lock_guard lock(mutex_);
    ended_ = true;
  }
  ready_.notify_all();
}

void CameraStream::push(FrameRef frame, std::chrono::nanoseconds readTime) {
  frame->arrival = std::chrono::steady_clock::now();
  {
    const std::lock_guard lock(mutex_);
    // Never full: the queue has a slot for every buffer of the pool.
    queue_[(head_ + size_) % queue_.size()] = std::move(frame);
    ++size_;
    ++stats_.frames;
    stats_.readTime += readTime;
  }
  ready_.notify_one();
}

CameraStream::Next CameraStream::next(FrameRef& out, std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  if (!ready_.wait_for(lock, timeout, [this] { return size_ > 0 || ended_; }))
    return Next::kTimeout;
  if (size_ == 0) return Next::kEnded;
  out = std::move(queue_[head_]);
  head_ = (head_ + 1) % queue_.size();
  --size_;
  return Next::kFrame;
}

CameraStreamStats CameraStream::stats() const {
  const std::lock_guard lock(mutex_);
  return stats_;
}

std::size_t CameraStream::queued() const {
  const std::lock_guard lock(mutex_);
  return size_;
}

}  // namespace surroundd::capture
