#include "daemon/live_cameras.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "capture/libcamera_source.hpp"
#include "capture/v4l2_probe.hpp"

namespace surroundd::daemon {
namespace {

constexpr std::string_view kAuto = "auto";

std::string where(const RigCamera& camera) {
  return fmt::format("camera '{}': {}", camera.calibration.name, camera.v4l2()->device.string());
}

// The capture nodes, in number order.
std::vector<capture::V4l2Node> captureNodes(const std::filesystem::path& dev) {
  std::vector<capture::V4l2Node> nodes;
  for (auto& node : capture::v4l2Nodes(dev)) {
    const auto device = capture::makeKernelV4l2Device();
    try {
      if (capture::probeV4l2(node.path, node.path.string(), *device).capture) {
        nodes.push_back(std::move(node));
      }
    } catch (const capture::CaptureError&) {
      // Not one to capture from (busy nodes still answer what they are).
    }
  }
  return nodes;
}

bool sameNode(const std::filesystem::path& a, const std::filesystem::path& b) {
  std::error_code error;
  return std::filesystem::equivalent(a, b, error) || a == b;
}

}  // namespace

void listCameras(std::ostream& out, const std::filesystem::path& dev) {
  const auto nodes = capture::v4l2Nodes(dev);
  int captureCount = 0;
  for (const auto& node : nodes) {
    const auto device = capture::makeKernelV4l2Device();
    capture::V4l2Probe probe;
    try {
      probe =
          capture::probeV4l2(node.path, node.path.string(), *device, capture::FrameRates::kListed);
    } catch (const capture::CaptureError& error) {
      out << error.what() << "\n";
      continue;
    }
    if (!probe.capture) continue;  // metadata, output and codec nodes
    ++captureCount;
    out << fmt::format("{}: '{}' (driver {}, {}){}\n", node.path.string(), probe.card, probe.driver,
                       probe.bus, probe.multiplanar ? ", multi-planar" : "");
    for (const auto& name : node.persistentNames) out << "  also " << name.string() << "\n";
    // What surroundd can take in full; the rest by name only (a driver like vivid offers dozens).
    std::vector<std::string> others;
    for (const auto& offer : probe.offers) {
      if (std::ranges::any_of(capture::kV4l2Formats, [&](const capture::V4l2FormatCode& code) {
            return code.fourcc == offer.fourcc;
          })) {
        out << "  " << capture::describe({offer}, capture::FrameRates::kListed) << "\n";
      } else {
        others.push_back(capture::fourccText(offer.fourcc));
      }
    }
    if (!others.empty()) {
      out << fmt::format("  and formats surroundd does not take: {}\n", fmt::join(others, " "));
    }
  }
  if (captureCount == 0) {
    out << fmt::format("no V4L2 capture device in {} ({} video nodes)\n", dev.string(),
                       nodes.size());
  }
  if (!capture::libcameraAvailable()) {
    out << "libcamera: this surroundd is built without it\n";
    return;
  }
  try {
    const auto cameras = capture::libcameraCameras();
    if (cameras.empty()) out << "libcamera: no camera\n";
    for (const auto& camera : cameras) out << "libcamera " << camera << "\n";
  } catch (const capture::CaptureError& error) {
    out << error.what() << "\n";
  }
}

std::vector<RigCamera> withAutoDevices(std::vector<RigCamera> cameras,
                                       std::vector<std::string>& said,
                                       const std::filesystem::path& dev) {
  const auto wantsAuto = [](const RigCamera& c) { return c.v4l2() && c.v4l2()->device == kAuto; };
  if (std::ranges::none_of(cameras, wantsAuto)) return cameras;
  const auto nodes = captureNodes(dev);
  auto next = nodes.begin();
  for (auto& camera : cameras) {
    if (!wantsAuto(camera)) continue;
    const auto named = [&](const capture::V4l2Node& node) {
      return std::ranges::any_of(cameras, [&](const RigCamera& other) {
        return other.v4l2() && other.v4l2()->device != kAuto &&
               sameNode(other.v4l2()->device, node.path);
      });
    };
    while (next != nodes.end() && named(*next)) ++next;
    if (next == nodes.end()) {
      std::vector<std::string> found;
      found.reserve(nodes.size());
      for (const auto& node : nodes) found.push_back(node.path.string());
      throw std::runtime_error(fmt::format(
          "camera '{}': device auto: no V4L2 capture device is left for it (found {}{}); name "
          "its device (surroundd --list-cameras shows them)",
          camera.calibration.name, nodes.size(),
          found.empty() ? "" : fmt::format(": {}", fmt::join(found, ", "))));
    }
    camera.v4l2()->device = next->path;
    said.push_back(fmt::format("camera '{}': device auto is {}{}", camera.calibration.name,
                               next->path.string(),
                               next->persistentNames.empty()
                                   ? ""
                                   : fmt::format(" ({})", next->persistentNames.front().string())));
    ++next;
  }
  return cameras;
}

std::vector<std::string> cameraDeviceProblems(const std::vector<RigCamera>& cameras) {
  std::vector<std::string> problems;
  for (const auto& camera : cameras) {
    if (!camera.v4l2()) continue;
    const auto device = capture::makeKernelV4l2Device();
    try {
      const auto probe = capture::probeV4l2(camera.v4l2()->device, where(camera), *device);
      if (!probe.capture) {
        problems.push_back(fmt::format("{} ('{}', driver {}): cannot capture video by streaming",
                                       where(camera), probe.card, probe.driver));
      } else if (capture::chooseV4l2Format(probe, *camera.v4l2()) == nullptr) {
        problems.push_back(
            fmt::format("{}: {}", where(camera), capture::notOffered(probe, *camera.v4l2())));
      }
    } catch (const capture::CaptureError& error) {
      problems.emplace_back(error.what());
    }
  }
  return problems;
}

}  // namespace surroundd::daemon
