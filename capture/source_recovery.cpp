#include "capture/source_recovery.hpp"

#include <algorithm>

#include <spdlog/spdlog.h>

namespace surroundd::capture {

namespace {

// Sources name their camera in their messages; the log line names it once.
std::string_view withoutCamera(std::string_view message, const std::string& camera) {
  const std::string prefix = fmt::format("camera '{}': ", camera);
  if (message.starts_with(prefix)) message.remove_prefix(prefix.size());
  return message;
}

}  // namespace

FaultLog::FaultLog(std::string camera, std::chrono::milliseconds interval)
    : camera_(std::move(camera)), interval_(interval) {}

bool FaultLog::holdingBack(Clock::time_point now) const {
  return windowStart_ && now - *windowStart_ < interval_;
}

void FaultLog::summary(Clock::time_point now, std::string_view latest) {
  const double seconds = std::chrono::duration<double>(now - *windowStart_).count();
  const std::string reopened = heldNotes_ == 0   ? std::string()
                               : heldNotes_ == 1 ? std::string(", reopened once")
                                                 : fmt::format(", reopened {} times", heldNotes_);
  spdlog::warn("camera '{}': {} more faults in {:.1f} s{}; the last: {}", camera_, heldFaults_,
               seconds, reopened, latest);
  ++lines_;
  heldFaults_ = 0;
  heldNotes_ = 0;
  lastHeld_.clear();
}

void FaultLog::fault(std::string_view message, Clock::time_point now) {
  message = withoutCamera(message, camera_);
  if (holdingBack(now)) {
    ++heldFaults_;
    ++leftOut_;
    lastHeld_ = message;
    return;
  }
  if (heldFaults_ > 0 || heldNotes_ > 0) {
    ++heldFaults_;  // this one, named as the last
    summary(now, message);
  } else {
    spdlog::warn("camera '{}': {}", camera_, message);
    ++lines_;
  }
  windowStart_ = now;
}

void FaultLog::note(std::string_view message, Clock::time_point now) {
  if (holdingBack(now)) {
    ++heldNotes_;
    ++leftOut_;
    return;
  }
  flush(now);
  spdlog::info("camera '{}': {}", camera_, message);
  ++lines_;
  windowStart_ = now;
}

void FaultLog::flushIfDue(Clock::time_point now) {
  if (!holdingBack(now)) flush(now);
}

void FaultLog::flush(Clock::time_point now) {
  if (heldFaults_ == 0 && heldNotes_ == 0) return;
  const std::string latest = lastHeld_.empty() ? std::string("a reopening") : lastHeld_;
  summary(now, latest);
  windowStart_ = now;
}

SourceRecovery::SourceRecovery(std::string camera, RecoverySettings settings)
    : camera_(std::move(camera)), settings_(settings), log_(camera_, settings_.logInterval) {}

SourceRecovery::Step SourceRecovery::onFault(std::string_view message, bool lost,
                                             Clock::time_point now) {
  ++faults_;
  ++inARow_;
  log_.fault(message, now);
  if (settings_.giveUpAfterFaults > 0 && inARow_ >= settings_.giveUpAfterFaults) {
    gaveUp_ = true;
    log_.flush(now);
    spdlog::error("camera '{}': {} faults in a row, giving up on this camera", camera_, inARow_);
    return Step::kGiveUp;
  }
  if (!lost && !lost_) return Step::kReadAgain;
  lost_ = true;
  backoff_ =
      backoff_.count() == 0 ? settings_.firstBackoff : std::min(backoff_ * 2, settings_.maxBackoff);
  return Step::kReopen;
}

void SourceRecovery::onFrame(Clock::time_point now) {
  inARow_ = 0;
  backoff_ = std::chrono::milliseconds(0);
  // Frames flow again after a burst: say how many faults were left out, once the interval is over.
  log_.flushIfDue(now);
}

void SourceRecovery::onReopened(Clock::time_point now) {
  lost_ = false;
  ++reopens_;
  log_.note(fmt::format("reopened after {} faults in a row", inARow_), now);
}

void SourceRecovery::onEnd(Clock::time_point now) { log_.flush(now); }

ReadStatus SourceRecovery::read(FrameSource& source, Frame& out, const Wait& wait) {
  if (gaveUp_) return ReadStatus::kEndOfStream;
  if (lost_) {
    if (!wait(backoff_)) return ReadStatus::kEndOfStream;
    try {
      source.reopen();
      onReopened(Clock::now());
    } catch (const CaptureError& e) {
      const std::string message =
          fmt::format("reopening failed (next try in {} ms): {}",
                      std::min(backoff_ * 2, settings_.maxBackoff).count(), e.what());
      return onFault(message, true, Clock::now()) == Step::kGiveUp ? ReadStatus::kEndOfStream
                                                                   : ReadStatus::kFault;
    }
  }
  out.concealedErrors = false;
  const ReadStatus status = source.read(out);
  const auto now = Clock::now();
  switch (status) {
    case ReadStatus::kFrame:
      if (out.concealedErrors) {
        ++faults_;
        log_.fault(source.lastError(), now);
      }
      onFrame(now);
      return ReadStatus::kFrame;
    case ReadStatus::kEndOfStream:
      onEnd(now);
      return ReadStatus::kEndOfStream;
    case ReadStatus::kFault:
    case ReadStatus::kLost:
      break;
  }
  const Step step = onFault(source.lastError(), status == ReadStatus::kLost, now);
  return step == Step::kGiveUp ? ReadStatus::kEndOfStream : ReadStatus::kFault;
}

}  // namespace surroundd::capture
