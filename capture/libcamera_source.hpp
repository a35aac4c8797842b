#pragma once
// A live camera through libcamera (Debian's libcamera-dev): the camera is picked by its id (or
// the first one), configured with one video stream of the lens's size in the first format of
// BGR, YUYV, NV12 that the pipeline handler offers, and run with a ring of requests. Frames carry
// the sensor's timestamps (CLOCK_MONOTONIC, like V4L2's) and leave read() as BGR.
//
// Built only where libcamera is found at configure time; elsewhere constructing one throws a
// CaptureError that says so. Faults at run time are read() statuses: a failed request is kFault;
// no frame within the timeout (a stalled or removed camera) stops and releases the camera and is
// kLost, and reopen() acquires and starts it again, as a V4L2 device is (the recovery policy,
// capture/source_recovery.hpp, decides when).

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "capture/frame_source.hpp"

namespace surroundd::capture {

struct LibcameraSettings {
  std::string camera;  // a camera id, or part of one; empty: the first camera
  cv::Size size{1280, 720};
  double fps = 30;  // the nominal rate (the pipeline handler picks the sensor mode)
  int buffers = 4;
  std::chrono::milliseconds timeout{500};
  bool operator==(const LibcameraSettings&) const = default;
};

// Whether this build has libcamera.
bool libcameraAvailable();

// The cameras libcamera finds, one line each: "<id> (<model>): <format> <smallest> to <largest>;
// ..." (a viewfinder stream's formats). Throws CaptureError where the camera manager does not
// start, or this build has no libcamera.
std::vector<std::string> libcameraCameras();

class LibcameraSource final : public FrameSource {
 public:
  // Throws CaptureError naming the camera: none matches (the message lists the cameras found),
  // it is busy, or it cannot give the size.
  LibcameraSource(std::string cameraName, LibcameraSettings settings);
  ~LibcameraSource() override;

  cv::Size frameSize() const override;
  PixelFormat pixelFormat() const override;
  Timestamp nominalPeriod() const override;
  ReadStatus read(Frame& out) override;
  const std::string& lastError() const override;
  void reopen() override;

 private:
  struct Impl;  // libcamera's types stay out of the header
  std::unique_ptr<Impl> impl_;
};

}  // namespace surroundd::capture
