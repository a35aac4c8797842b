#include "capture/camera_stream.hpp"

#include <spdlog/spdlog.h>

namespace surroundd::capture {
namespace {

// How long the capture thread waits for a free buffer before it checks whether it should stop.
constexpr std::chrono::milliseconds kPoolWait{100};

}  // namespace

CameraStream::CameraStream(std::string name, std::unique_ptr<FrameSource> source,
                           std::size_t poolFrames, int maxConsecutiveFaults)
    : name_(std::move(name)),
      source_(std::move(source)),
      pool_(poolFrames, source_->frameSize()),
      nominalPeriod_(source_->nominalPeriod()),
      repeatsOnePicture_(source_->repeatsOnePicture()),
      maxConsecutiveFaults_(maxConsecutiveFaults),
      queue_(poolFrames) {}

CameraStream::~CameraStream() { stop(); }

void CameraStream::start() {
  thread_ = std::thread([this] { run(); });
}

void CameraStream::stop() {
  stopping_ = true;
  if (thread_.joinable()) thread_.join();
}

void CameraStream::run() {
  int consecutiveFaults = 0;
  std::uint64_t sequence = 0;
  while (!stopping_) {
    FrameRef frame = pool_.acquire(kPoolWait);
    if (!frame) continue;
    const auto readStart = std::chrono::steady_clock::now();
    const ReadStatus status = source_->read(*frame);
    if (status == ReadStatus::kFrame) {
      consecutiveFaults = 0;
      frame->sequence = sequence++;
      push(std::move(frame), std::chrono::steady_clock::now() - readStart);
      continue;
    }
    if (status == ReadStatus::kFault) {
      {
        const std::lock_guard lock(mutex_);
        ++stats_.faults;
      }
      // One line per fault: a replay gives up after maxConsecutiveFaults_ of them; a live source
      // paces its own retries (a timeout or a reopening backoff per fault).
      spdlog::warn("camera '{}': {}", name_, source_->lastError());
      ++consecutiveFaults;
      if (maxConsecutiveFaults_ == 0 || consecutiveFaults < maxConsecutiveFaults_) continue;
      spdlog::error("camera '{}': {} faults in a row, giving up on this camera", name_,
                    consecutiveFaults);
    } else {
      spdlog::info("camera '{}': end of stream after {} frames", name_, sequence);
    }
    break;
  }
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
