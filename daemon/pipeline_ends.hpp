#pragma once
// The pipeline's two ends, opened from the config: its cameras (file replay, V4L2, libcamera) and
// its outputs' sinks (video, network, HTTP, window, display, snapshot).
//
// Error policy: throws (CaptureError, EncoderError, RenderError, std::runtime_error) with a message
// naming the camera, file, address or device that could not be opened.

#include <memory>
#include <string>
#include <vector>

#include "capture/camera_health.hpp"
#include "capture/camera_stream.hpp"
#include "daemon/config.hpp"
#include "render/frame_sink.hpp"
#include "render/http_stream_sink.hpp"

namespace surroundd::daemon {

// One CameraStream per camera (not started yet), each checked against its lens's calibrated size.
std::vector<std::unique_ptr<capture::CameraStream>> openCameras(const Config& config);
std::vector<std::string> cameraNames(const Config& config);
// Each camera's frozen check, from its `health.frozen_check` and its opened source.
void setUpHealthChecks(const Config& config,
                       const std::vector<std::unique_ptr<capture::CameraStream>>& cameras,
                       capture::CameraHealthMonitor& health);

// An HTTP output; for a surround stream its page offers every view, `view` first.
std::unique_ptr<render::HttpStreamSink> openHttp(const OutputConfig& output, ViewKind view);
// Any other picture output. Video encodes on a thread of its own; with `latestWins` its queue
// drops the oldest picture instead of waiting.
std::unique_ptr<render::FrameSink> openSink(const OutputConfig& output, cv::Size videoSize,
                                            double nominalFps, bool latestWins);

}  // namespace surroundd::daemon
