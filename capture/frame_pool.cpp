#include "capture/frame.hpp"

namespace surroundd::capture {

void endLoan(Frame& frame) noexcept {
  if (!frame.loan.lender) return;
  // The picture first: the lender may unmap the buffer once it has it back.
  frame.image = frame.loan.own;
  frame.loan.own = cv::Mat();
  frame.dmabuf = {};
  frame.loan.lender->giveBack(frame.loan.buffer);
  frame.loan.lender.reset();
}

namespace detail {
struct FramePoolState {
  std::vector<std::unique_ptr<Frame>> storage;  // owns every frame for the pool's whole life
  std::vector<Frame*> free;  // reserved to storage.size(): push_back never allocates
  mutable std::mutex mutex;
  std::condition_variable returned;
};

void FrameReturner::operator()(Frame* frame) const noexcept {
  endLoan(*frame);
  {
    const std::lock_guard lock(pool->mutex);
    pool->free.push_back(frame);
  }
  pool->returned.notify_one();
}
}  // namespace detail

FramePool::FramePool(std::size_t count, cv::Size size, PixelFormat format)
    : state_(std::make_shared<detail::FramePoolState>()), size_(size), format_(format) {
  state_->storage.reserve(count);
  state_->free.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    auto frame = std::make_unique<Frame>();
    frame->image.create(heldSize(format, size), heldType(format));
    frame->format = format;
    state_->free.push_back(frame.get());
    state_->storage.push_back(std::move(frame));
  }
}

FrameRef FramePool::take(std::unique_lock<std::mutex>& lock) {
  Frame* frame = state_->free.back();
  state_->free.pop_back();
  lock.unlock();
  return FrameRef(frame, detail::FrameReturner{state_});
}

FrameRef FramePool::acquire(std::chrono::milliseconds timeout) {
  std::unique_lock lock(state_->mutex);
  if (!state_->returned.wait_for(lock, timeout, [this] { return !state_->free.empty(); })) {
    return FrameRef(nullptr, detail::FrameReturner{state_});
  }
  return take(lock);
}

FrameRef FramePool::tryAcquire() {
  std::unique_lock lock(state_->mutex);
  if (state_->free.empty()) {
    return FrameRef(nullptr, detail::FrameReturner{state_});
  }
  return take(lock);
}

std::size_t FramePool::capacity() const { return state_->storage.size(); }

std::size_t FramePool::available() const {
  const std::lock_guard lock(state_->mutex);
  return state_->free.size();
}

}  // namespace surroundd::capture
