#pragma once
// One interface for every camera: file replay now, V4L2 and libcamera later, fakes in tests.
//
// Error policy of capture/: constructors and open() throw CaptureError with a message that names
// the camera and the device or file (start-up boundary). read() never throws: a fault at run time
// is a ReadStatus plus lastError(), so a capture thread never unwinds through the pipeline. What
// happens after a fault (reading again, reopening, giving up, logging) is not the source's choice:
// one policy decides it for every kind (SourceRecovery, capture/source_recovery.hpp).

#include <stdexcept>
#include <string>

#include "capture/frame.hpp"

namespace surroundd::capture {

class CaptureError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class ReadStatus {
  kFrame,        // `out` holds a new frame
  kEndOfStream,  // a finite source ran out (and does not loop)
  kFault,        // this read lost a frame (corrupt, undecodable); lastError() says why. The next
                 // read() goes on.
  kLost,         // the device stopped delivering or went away, and is closed; lastError() says
                 // why. reopen() before reading again.
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  FrameSource() = default;
  FrameSource(const FrameSource&) = delete;
  FrameSource& operator=(const FrameSource&) = delete;

  // Size of the pictures this source delivers; known once the source is constructed.
  virtual cv::Size frameSize() const = 0;
  // How it holds them (common/pixel_format.hpp); known once the source is constructed, and kept
  // by reopen(). BGR unless a source says otherwise.
  virtual PixelFormat pixelFormat() const { return PixelFormat::kBgr; }
  // Nominal frame period, used for pacing and health deadlines.
  virtual Timestamp nominalPeriod() const = 0;
  // Blocks until the next frame is decoded or captured into `out` (whose image holds a picture of
  // frameSize() in pixelFormat()).
  virtual ReadStatus read(Frame& out) = 0;
  virtual const std::string& lastError() const = 0;
  // Opens the device again after kLost, keeping frameSize() and nominalPeriod(). Throws
  // CaptureError when it cannot (yet). A source that never reports kLost keeps this default, which
  // cannot.
  virtual void reopen() { throw CaptureError(lastError()); }
  // True for a source that shows one picture over and over by design (a still picture, looped):
  // its frames repeat without anything being wrong. Known once the source is constructed.
  virtual bool repeatsOnePicture() const { return false; }
  // From the next read on, frames are lent the source's own buffers where it can, rather than
  // copied out of them: their `dmabuf` says where a GPU can import the picture (capture/
  // frame.hpp). Returns why it cannot; nullptr when it does. Before the source is read.
  virtual const char* lendBuffers() { return "its frames are not in a driver's buffers"; }
};

}  // namespace surroundd::capture
