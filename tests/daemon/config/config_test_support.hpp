#pragma once
// The config tests' fixture: a good two-camera config, variations of it in a fresh folder, and the
// messages loading gives.

#include <filesystem>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "daemon/config/config.hpp"
#include "tests/support/temp_dir.hpp"

namespace surroundd::daemon {

// Two cameras are enough for the schema; line numbers below refer to this text.
inline constexpr std::string_view kGoodConfig = R"(logging:
  level: debug
rig:
  cameras:
    - name: front
      source: {file: front.mkv}
      lens: {model: pinhole, width_px: 640, height_px: 360, fx_px: 300, fy_px: 300, cx_px: 319.5, cy_px: 179.5}
      mount: {x_m: 1.0, y_m: 0.0, z_m: 1.8, yaw_deg: 0, pitch_deg: -20}
    - name: left
      source: {file: left.mkv}
      lens: {model: fisheye, width_px: 640, height_px: 360, fx_px: 200, fy_px: 200, cx_px: 320, cy_px: 180, distortion: [0.01, 0, 0, 0]}
      mount: {x_m: 0.0, y_m: 0.9, z_m: 1.0, yaw_deg: 90, pitch_deg: -40}
capture:
  pacing: as_fast_as_possible
  sync_tolerance_ms: 5
render:
  width_px: 640
  height_px: 360
outputs:
  - {type: video, path: out/mosaic.mp4, crf: 18}
  - {type: snapshot, path: out/mosaic.png, at_s: 0.5}
)";

class ConfigTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_.write("front.mkv", "");
    dir_.write("left.mkv", "");
  }

  // The good config with both cameras live: front on /dev/video0, left's source as given.
  std::filesystem::path liveConfigWith(std::string_view leftSource) {
    std::string text(kGoodConfig);
    const auto replace = [&](std::string_view from, std::string_view to) {
      text.replace(text.find(from), from.size(), to);
    };
    replace("source: {file: front.mkv}", "source: {device: /dev/video0}");
    replace("source: {file: left.mkv}", leftSource);
    return dir_.write("config.yaml", text);
  }

  // The good config with `from` replaced by `to` (which must occur).
  std::filesystem::path configWith(std::string_view from, std::string_view to) {
    std::string text(kGoodConfig);
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return dir_.write("config.yaml", text);
  }

  // The messages loadConfig throws for `file`; empty if it loads.
  static std::vector<std::string> errorsOf(const std::filesystem::path& file) {
    try {
      loadConfig(file);
    } catch (const ConfigError& e) {
      return e.messages();
    }
    return {};
  }

  // Exactly one message, which must contain every part.
  void expectOneError(std::string_view from, std::string_view to,
                      std::initializer_list<std::string_view> parts) {
    const auto file = configWith(from, to);
    const auto messages = errorsOf(file);
    ASSERT_EQ(messages.size(), 1u) << ::testing::PrintToString(messages);
    for (const auto part : parts) EXPECT_THAT(messages[0], ::testing::HasSubstr(std::string(part)));
  }

  std::string where(int line, int column) const {
    return (dir_ / "config.yaml").string() + ":" + std::to_string(line) + ":" +
           std::to_string(column);
  }

  testing::TempDir dir_;
};

}  // namespace surroundd::daemon
