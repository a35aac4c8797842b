#include "capture/v4l2_probe.hpp"

#include <algorithm>
#include <charconv>
#include <cstring>
#include <system_error>

#include <fmt/format.h>

namespace surroundd::capture {
namespace {

std::string text(const std::uint8_t* field, std::size_t size) {
  const auto* begin = reinterpret_cast<const char*>(field);
  return {begin, strnlen(begin, size)};
}

// The number of a node named videoN; -1 for other names.
int videoNumber(const std::filesystem::path& node) {
  const std::string name = node.filename().string();
  if (!name.starts_with("video")) return -1;
  int number = -1;
  const auto [end, error] = std::from_chars(name.data() + 5, name.data() + name.size(), number);
  return error == std::errc() && end == name.data() + name.size() && name.size() > 5 ? number : -1;
}

}  // namespace

V4l2Probe probeV4l2(V4l2Device& opened, const std::string& where, FrameRates rates) {
  v4l2_capability capability{};
  if (const int error = opened.ioctl(VIDIOC_QUERYCAP, &capability); error != 0) {
    throw CaptureError(
        fmt::format("{}: not a V4L2 device ({})", where, std::generic_category().message(error)));
  }
  V4l2Probe probe;
  probe.card = text(capability.card, sizeof capability.card);
  probe.driver = text(capability.driver, sizeof capability.driver);
  probe.bus = text(capability.bus_info, sizeof capability.bus_info);
  const std::uint32_t caps = (capability.capabilities & V4L2_CAP_DEVICE_CAPS) != 0
                                 ? capability.device_caps
                                 : capability.capabilities;
  const bool singlePlanar = (caps & V4L2_CAP_VIDEO_CAPTURE) != 0;
  const bool multiPlanar = (caps & V4L2_CAP_VIDEO_CAPTURE_MPLANE) != 0;
  probe.capture = (singlePlanar || multiPlanar) && (caps & V4L2_CAP_STREAMING) != 0;
  if (!probe.capture) return probe;
  // Most embedded capture drivers (i.MX, Rockchip, TI) speak only the multi-planar API, even for
  // one-plane formats; a driver that speaks both is used through the single-planar one.
  probe.multiplanar = !singlePlanar;
  probe.bufferType =
      probe.multiplanar ? V4L2_BUF_TYPE_VIDEO_CAPTURE_MPLANE : V4L2_BUF_TYPE_VIDEO_CAPTURE;
  probe.offers = offersOf(opened, probe.bufferType, rates);
  return probe;
}

V4l2Probe probeV4l2(const std::filesystem::path& node, const std::string& where, V4l2Device& device,
                    FrameRates rates) {
  if (const int error = device.open(node.string()); error != 0) {
    throw CaptureError(
        fmt::format("{}: cannot open: {}", where, std::generic_category().message(error)));
  }
  try {
    auto probe = probeV4l2(device, where, rates);
    device.close();
    return probe;
  } catch (...) {
    device.close();
    throw;
  }
}

const V4l2FormatCode* chooseV4l2Format(const V4l2Probe& probe, const V4l2Settings& settings) {
  for (const auto& candidate : kV4l2Formats) {
    if (settings.format != V4l2Format::kAuto && settings.format != candidate.format) continue;
    if (candidate.planes > 1 && !probe.multiplanar) continue;
    const auto offer = std::ranges::find(probe.offers, candidate.fourcc, &V4l2Offer::fourcc);
    if (offer != probe.offers.end() && offer->has(settings.size)) return &candidate;
  }
  return nullptr;
}

std::string notOffered(const V4l2Probe& probe, const V4l2Settings& settings) {
  return fmt::format("does not offer {} {}x{} (it offers{}: {})", toString(settings.format),
                     settings.size.width, settings.size.height,
                     probe.multiplanar ? ", multi-planar" : "", describe(probe.offers));
}

std::vector<V4l2Node> v4l2Nodes(const std::filesystem::path& dev) {
  std::vector<V4l2Node> nodes;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(dev, error)) {
    if (videoNumber(entry.path()) >= 0) nodes.push_back({entry.path(), {}});
  }
  std::ranges::sort(nodes, {}, [](const V4l2Node& n) { return videoNumber(n.path); });
  for (const char* folder : {"v4l/by-path", "v4l/by-id"}) {
    std::vector<std::filesystem::path> links;
    for (const auto& entry : std::filesystem::directory_iterator(dev / folder, error)) {
      links.push_back(entry.path());
    }
    std::ranges::sort(links);
    for (const auto& link : links) {
      const auto target = std::filesystem::canonical(link, error);
      if (error) continue;
      for (auto& node : nodes) {
        if (std::filesystem::equivalent(node.path, target, error)) {
          node.persistentNames.push_back(link);
        }
      }
    }
  }
  return nodes;
}

}  // namespace surroundd::capture
