#pragma once
// surroundd run as a service by a test: a config of the test's around the small synthetic
// recording's rig, looping; the control socket asked as a patient client; waits on the log and
// the frame sets.

#include <chrono>
#include <filesystem>
#include <memory>
#include <regex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include "daemon/config/rig_yaml.hpp"
#include "daemon/control/control_protocol.hpp"
#include "tests/support/child_process.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::daemon {

using namespace std::chrono_literals;

// A function: a static path's construction could throw before main (cert-err58-cpp).
inline std::filesystem::path recording() {
  return std::filesystem::path(SURROUNDD_FIXTURE_DIR) / "synth_small";
}

class ServiceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // The recording's rig, looping: the daemon runs until it is told to stop.
    auto cameras = loadRigFile(recording() / "rig.yaml");
    for (auto& camera : cameras) camera.replayedFile()->loop = true;
    writeRigFile(dir_ / "rig.yaml", cameras, "looping replay");
    std::filesystem::remove_all(socket_.parent_path());
  }
  void TearDown() override { std::filesystem::remove_all(socket_.parent_path()); }

  std::filesystem::path writeConfig(std::string_view outputs, std::string_view extra = "") const {
    return dir_.write("config.yaml", fmt::format(R"(rig: {{file: rig.yaml}}
pipeline: {{threads: 2}}
panorama: {{width_px: 512, height_px: 256, cache_dir: lut-cache}}
render: {{width_px: 320, height_px: 240, view: orbit}}
control: {{socket: {}}}
{}
outputs:
{})",
                                                 socket_.string(), extra, outputs));
  }

  std::unique_ptr<testing::ChildProcess> start(const std::filesystem::path& config,
                                               std::vector<std::string> environment = {}) const {
    return std::make_unique<testing::ChildProcess>(
        std::vector<std::string>{SURROUNDD_EXECUTABLE, "--config", config.string()},
        dir_ / "log.txt", std::move(environment));
  }

  // As a patient client: a "busy ... try again" (the pipeline thread gave no answer within the
  // server's 10 s, as while it builds a view's table under a sanitizer on a loaded machine) is
  // asked again, twice at most.
  ControlReply request(std::string_view line) const {
    ControlReply reply = sendControlRequest(socket_, line, 20s);
    for (int again = 0; again < 2 && !reply.ok && reply.body.find("try again") != std::string::npos;
         ++again) {
      reply = sendControlRequest(socket_, line, 20s);
    }
    return reply;
  }

  // Frame sets of the running pipeline, from `status` (waits for the socket to appear).
  std::uint64_t frameSets(testing::ChildProcess& surroundd) const {
    for (auto deadline = std::chrono::steady_clock::now() + 30s;
         std::chrono::steady_clock::now() < deadline && surroundd.running();
         std::this_thread::sleep_for(50ms)) {
      if (!std::filesystem::exists(socket_)) continue;
      const auto reply = request("status");
      std::smatch match;
      if (reply.ok && std::regex_search(reply.body, match, std::regex("^([0-9]+) frame sets"))) {
        return std::stoull(match[1]);
      }
    }
    ADD_FAILURE() << "no status from surroundd: " << surroundd.output();
    return 0;
  }
  // Waits until surroundd's log says `text`, at most 30 s.
  static void waitForLog(testing::ChildProcess& surroundd, std::string_view text) {
    for (auto deadline = std::chrono::steady_clock::now() + 30s;
         surroundd.output().find(text) == std::string::npos; std::this_thread::sleep_for(20ms)) {
      if (std::chrono::steady_clock::now() > deadline || !surroundd.running()) {
        ADD_FAILURE() << "surroundd never logged '" << text << "': " << surroundd.output();
        return;
      }
    }
  }
  // The start-up time in `status`, checked to lie between 0 and the time since `since` (when the
  // test started what it counts from) and to have its limits beside it.
  void expectFirstPictureWithin(std::string_view from,
                                std::chrono::steady_clock::time_point since) const {
    const auto status = request("status");
    const double upTo =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
    std::smatch match;
    ASSERT_TRUE(std::regex_search(
        status.body, match,
        std::regex(fmt::format(R"(first picture: ([0-9.]+) s after the {} started \(FMVSS 111: <= )"
                               R"(2\.0 s, (not )?met; target <= 1\.0 s, (not )?met\))",
                               from))))
        << status.body;
    EXPECT_GT(std::stod(match[1]), 0);
    EXPECT_LT(std::stod(match[1]), upTo);
  }
  // Waits until the pipeline has gone through at least `sets` frame sets.
  void waitForSets(testing::ChildProcess& surroundd, std::uint64_t sets) const {
    const auto deadline = std::chrono::steady_clock::now() + 30s;
    while (frameSets(surroundd) < sets && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(50ms);
    }
  }

  testing::TempDir dir_;
  // Short: a socket path must fit in 108 bytes.
  std::filesystem::path socket_ =
      std::filesystem::temp_directory_path() / fmt::format("sd-svc-{}", ::getpid()) / "c.sock";
};

}  // namespace surroundd::daemon
