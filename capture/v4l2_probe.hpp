#pragma once
// What a V4L2 node is and offers, asked without streaming: read once by V4l2Source to negotiate,
// by `surroundd --check-config` to check a camera's format and size before anything starts, and by
// `surroundd --list-cameras` to show what is there. Also the capture nodes of a machine, with the
// persistent names udev gives them (/dev/v4l/by-path, /dev/v4l/by-id).

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "capture/v4l2_device.hpp"
#include "capture/v4l2_formats.hpp"
#include "capture/v4l2_source.hpp"

namespace surroundd::capture {

struct V4l2Probe {
  std::string card, driver, bus;
  bool capture = false;      // a video capture node that streams
  bool multiplanar = false;  // captured through the multi-planar API (the only one it speaks)
  std::uint32_t bufferType = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  std::vector<V4l2Offer> offers;  // of bufferType; empty when not a capture node
};

// Asks an opened device (each size's frame rates only where `rates` says). Throws CaptureError
// "<where>: not a V4L2 device (...)".
V4l2Probe probeV4l2(V4l2Device& opened, const std::string& where,
                    FrameRates rates = FrameRates::kLeftOut);

// Opens the node, asks it and closes it. Throws CaptureError "<where>: cannot open: ..." or as
// above.
V4l2Probe probeV4l2(const std::filesystem::path& node, const std::string& where, V4l2Device& device,
                    FrameRates rates = FrameRates::kLeftOut);

// The format V4l2Source takes for these settings: the first of kV4l2Formats that the settings
// allow and the device offers at their size; null when none.
const V4l2FormatCode* chooseV4l2Format(const V4l2Probe& probe, const V4l2Settings& settings);

// "does not offer NV12 1280x720 (it offers, multi-planar: YUYV 640x480; ...)".
std::string notOffered(const V4l2Probe& probe, const V4l2Settings& settings);

// The video nodes under `dev` (video0, video1, ... in number order) and, for each, the names in
// dev/v4l/by-path and dev/v4l/by-id that lead to it.
struct V4l2Node {
  std::filesystem::path path;
  std::vector<std::filesystem::path> persistentNames;
};
std::vector<V4l2Node> v4l2Nodes(const std::filesystem::path& dev = "/dev");

}  // namespace surroundd::capture
