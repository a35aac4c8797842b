#include "render/outputs/queued_sink.hpp"

#include <fmt/format.h>

namespace surroundd::render {

QueuedSink::QueuedSink(std::unique_ptr<FrameSink> sink, cv::Size size, std::size_t depth,
                       WhenFull whenFull)
    : sink_(std::move(sink)),
      whenFull_(whenFull),
      depth_(std::max<std::size_t>(depth, 1)),
      queue_(depth_ + 1) {
  // In the format its pictures come in where the sink takes I420 (a view gathered through its
  // table); a slot is made again, once, when they change format (a view drawn by OpenGL: BGR).
  const bool i420 = sink_->takesI420();
  for (std::size_t i = 0; i < queue_.size(); ++i) {
    slots_.emplace_back(i420 ? cv::Size(size.width, size.height * 3 / 2) : size,
                        i420 ? CV_8UC1 : CV_8UC3);
    free_.push_back(i);
  }
  worker_ = std::thread([this] { work(); });
}

QueuedSink::~QueuedSink() { stopWorker(); }

void QueuedSink::stopWorker() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  if (worker_.joinable()) worker_.join();
}

void QueuedSink::work() {
  std::unique_lock lock(mutex_);
  for (;;) {
    changed_.wait(lock, [this] { return size_ > 0 || stopping_; });
    if (size_ == 0) return;  // stopping, and everything queued has been consumed
    const Item item = queue_[head_];
    head_ = (head_ + 1) % queue_.size();
    --size_;
    lock.unlock();
    try {
      sink_->consume(slots_[item.slot], item.time);
    } catch (...) {
      lock.lock();
      failure_ = std::current_exception();
      free_.push_back(item.slot);
      changed_.notify_all();
      return;
    }
    lock.lock();
    free_.push_back(item.slot);
    changed_.notify_all();
  }
}

void QueuedSink::consume(const cv::Mat& picture, const PictureTime& time) {
  std::size_t slot = 0;
  {
    std::unique_lock lock(mutex_);
    if (whenFull_ == WhenFull::kWait) {
      changed_.wait(lock, [this] { return size_ < depth_ || failure_; });
    } else if (size_ == depth_) {
      // The oldest waiting picture gives way to this newer one.
      free_.push_back(queue_[head_].slot);
      head_ = (head_ + 1) % queue_.size();
      --size_;
      ++dropped_;
    }
    if (failure_) std::rethrow_exception(failure_);
    slot = free_.back();
    free_.pop_back();
  }
  // The slot is this thread's until it is queued.
  picture.copyTo(slots_[slot]);
  {
    const std::lock_guard lock(mutex_);
    queue_[(head_ + size_) % queue_.size()] = {slot, time};
    ++size_;
  }
  changed_.notify_all();
}

void QueuedSink::finish(const cv::Mat& lastFrame, std::chrono::nanoseconds lastTime) {
  stopWorker();  // after it has consumed everything queued
  if (failure_) std::rethrow_exception(failure_);
  sink_->finish(lastFrame, lastTime);
}

std::string QueuedSink::describe() const {
  const std::uint64_t drops = dropped();
  return drops == 0
             ? sink_->describe()
             : fmt::format("{}; {} pictures dropped (output too slow)", sink_->describe(), drops);
}

bool QueuedSink::wantsFrame(std::chrono::nanoseconds streamTime) const {
  return sink_->wantsFrame(streamTime);
}

std::uint64_t QueuedSink::dropped() const {
  const std::lock_guard lock(mutex_);
  return dropped_;
}

}  // namespace surroundd::render
