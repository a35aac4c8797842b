#include "tools/synth/encode_worker.hpp"

namespace surroundd::synth {

EncodeWorker::EncodeWorker(render::VideoEncoderSettings settings, int depth)
    : settings_(std::move(settings)), slots_(static_cast<std::size_t>(depth)) {
  for (auto& slot : slots_) slot.image.create(settings_.size, CV_8UC3);
  thread_ = std::thread([this] { run(); });
}

EncodeWorker::~EncodeWorker() {
  {
    const std::lock_guard lock(mutex_);
    closing_ = true;
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void EncodeWorker::rethrowIfFailed() {
  if (error_) std::rethrow_exception(error_);
}

cv::Mat& EncodeWorker::acquire() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return queued_ < slots_.size() || error_; });
  rethrowIfFailed();
  return slots_[head_].image;
}

void EncodeWorker::submit(std::chrono::nanoseconds timestamp) {
  {
    const std::lock_guard lock(mutex_);
    rethrowIfFailed();
    slots_[head_].timestamp = timestamp;
    head_ = (head_ + 1) % slots_.size();
    ++queued_;
  }
  changed_.notify_all();
}

void EncodeWorker::finish() {
  {
    const std::lock_guard lock(mutex_);
    closing_ = true;
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
  rethrowIfFailed();
}

void EncodeWorker::run() {
  try {
    render::VideoEncoder encoder(settings_);
    for (;;) {
      Slot* slot = nullptr;
      {
        std::unique_lock lock(mutex_);
        changed_.wait(lock, [&] { return queued_ > 0 || closing_; });
        if (queued_ == 0) break;  // closing and drained
        slot = &slots_[tail_];
      }
      // The slot is not reused by the caller until queued_ drops, so it is read without the lock.
      encoder.write(slot->image, slot->timestamp);
      {
        const std::lock_guard lock(mutex_);
        tail_ = (tail_ + 1) % slots_.size();
        --queued_;
      }
      changed_.notify_all();
    }
    encoder.close();
  } catch (...) {
    const std::lock_guard lock(mutex_);
    error_ = std::current_exception();
    changed_.notify_all();
  }
}

}  // namespace surroundd::synth
