#pragma once
// The V4L2 capture devices of vivid, the kernel's virtual video test driver, which stream its
// test pattern (75% colour bars by default) like cameras: scripts/device-vm.sh's machine has four.

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "capture/v4l2_source.hpp"

namespace surroundd::testing {

// Every vivid capture device, in the order the driver made them.
inline std::vector<std::filesystem::path> vividCameras() {
  std::vector<std::pair<std::string, std::filesystem::path>> found;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/sys/class/video4linux", ec)) {
    std::ifstream nameFile(entry.path() / "name");
    std::string name;
    std::getline(nameFile, name);
    if (name.starts_with("vivid-") && name.ends_with("-vid-cap")) {
      found.emplace_back(name, std::filesystem::path("/dev") / entry.path().filename());
    }
  }
  std::ranges::sort(found);
  std::vector<std::filesystem::path> devices;
  devices.reserve(found.size());
  for (const auto& [name, device] : found) devices.push_back(device);
  return devices;
}

// A vivid device's settings for a camera of `format` and `size`.
inline capture::V4l2Settings vividSettings(const std::filesystem::path& device,
                                           capture::V4l2Format format, cv::Size size = {640, 360}) {
  capture::V4l2Settings settings;
  settings.device = device;
  settings.size = size;
  settings.format = format;
  settings.timeout = std::chrono::milliseconds(3000);  // an emulated CPU draws the bars slowly
  return settings;
}

// vivid's 75% colour bars, left to right, in BGR: white, yellow, cyan, green, magenta, red, blue,
// black.
inline constexpr std::array<std::array<int, 3>, 8> kVividBars{{{191, 191, 191},
                                                               {0, 191, 191},
                                                               {191, 191, 0},
                                                               {0, 191, 0},
                                                               {191, 0, 191},
                                                               {0, 0, 191},
                                                               {191, 0, 0},
                                                               {0, 0, 0}}};

}  // namespace surroundd::testing
