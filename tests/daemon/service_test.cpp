// surroundd as a service, end to end: the control socket and surroundctl, reload with a bad and a
// good config (SIGHUP and `reload`), SIGTERM leaving playable files, and the watchdog going quiet
// when a stage stalls. The rig replays the small synthetic recording in a loop, in real time.

#include <algorithm>
#include <functional>
#include <regex>
#include <thread>

#include <fcntl.h>
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sys/stat.h>
#include <unistd.h>

#include "daemon/config/rig_yaml.hpp"
#include "daemon/control/control_protocol.hpp"
#include "tests/daemon/service_test_support.hpp"
#include "tests/support/child_process.hpp"
#include "tests/support/http_client.hpp"
#include "tests/support/notify_socket.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::daemon {
namespace {

using ::testing::HasSubstr;

// Issue 50: no program had --version ("'--version' needs a value"), and -c FILE and
// --config=FILE were refused. Every program says its version and the optional parts built in.
TEST_F(ServiceTest, EveryProgramSaysItsVersionAndTheConfigTakesEveryForm) {
  for (const auto& [program, name] :
       {std::pair{std::string(SURROUNDD_EXECUTABLE), "surroundd"},
        std::pair{std::string(SURROUNDCTL_EXECUTABLE), "surroundctl"}}) {
    testing::ChildProcess version({program, "--version"}, dir_ / "version.txt");
    EXPECT_EQ(version.wait(), 0) << name;
    EXPECT_THAT(version.output(), AllOf(HasSubstr(std::string(name) + " 0."),
                                        HasSubstr("\nbuilt with: "), HasSubstr("\nwithout: ")))
        << name;
  }
  const auto config = writeConfig("  - {type: snapshot, stream: mosaic, path: out/m.png}");
  for (const std::vector<std::string>& form :
       {std::vector<std::string>{"-c", config.string()},
        std::vector<std::string>{"--config=" + config.string()}}) {
    std::vector<std::string> arguments{SURROUNDD_EXECUTABLE};
    arguments.insert(arguments.end(), form.begin(), form.end());
    arguments.emplace_back("--check-config");
    testing::ChildProcess check(arguments, dir_ / "check.txt");
    EXPECT_EQ(check.wait(), 0) << check.output();
    EXPECT_THAT(check.output(), HasSubstr(": good ("));
  }
}

TEST_F(ServiceTest, ControlRequestsRoundTripAndSigtermLeavesPlayableFiles) {
  const auto launched = std::chrono::steady_clock::now();
  auto surroundd = start(writeConfig(R"(  - {type: video, stream: surround, path: out/orbit.mp4}
  - {type: video, stream: mosaic, path: out/mosaic.mkv}
  - {type: http, stream: surround, listen: "127.0.0.1:0"})"));
  waitForSets(*surroundd, 10);

  const auto status = request("status");
  ASSERT_TRUE(status.ok) << status.body;
  EXPECT_THAT(status.body, HasSubstr("front ok, right ok, back ok, left ok"));
  for (const char* stage : {"sync", "stitch", "correct", "render", "read-back", "output"}) {
    EXPECT_THAT(status.body, ::testing::ContainsRegex(fmt::format("stage {} +p50", stage)));
  }
  EXPECT_THAT(status.body, HasSubstr("latency capture to output: p50"));
  // The figures beside their limits; the start-up counts from the process's start.
  EXPECT_THAT(status.body,
              ::testing::ContainsRegex(
                  R"(frame rate: [0-9.]+ fps \(ISO 16505 / IEC 63033-3: >= 30 fps, )"));
  EXPECT_THAT(status.body, HasSubstr("ms (ISO 16505 / IEC 63033-3: p99 < 200 ms, "));
  expectFirstPictureWithin("process", launched);

  const auto metrics = request("metrics");
  ASSERT_TRUE(metrics.ok);
  std::smatch match;
  ASSERT_TRUE(std::regex_search(metrics.body, match,
                                std::regex("\nsurroundd_frame_sets_total ([0-9]+)\n")));
  EXPECT_GE(std::stoi(match[1]), 10);
  EXPECT_THAT(metrics.body, HasSubstr("surroundd_latency_seconds{quantile=\"0.99\"}"));
  EXPECT_THAT(metrics.body, HasSubstr("surroundd_camera_healthy{camera=\"left\"} 1"));
  ASSERT_TRUE(std::regex_search(metrics.body, match,
                                std::regex("\nsurroundd_startup_seconds\\{since=\"process\"\\} "
                                           "([0-9.]+)\n")))
      << metrics.body;
  EXPECT_GT(std::stod(match[1]), 0);
  EXPECT_LT(std::stod(match[1]),
            std::chrono::duration<double>(std::chrono::steady_clock::now() - launched).count());
  EXPECT_THAT(surroundd->output(), HasSubstr("first picture out "));

  // The view switches: the next snapshot is a top view, unlike the orbit before it.
  const auto before = request("snapshot");
  ASSERT_TRUE(before.ok) << before.body;
  const auto orbit =
      cv::imdecode(std::vector<uchar>(before.body.begin(), before.body.end()), cv::IMREAD_COLOR);
  ASSERT_EQ(orbit.size(), cv::Size(320, 240));
  ASSERT_TRUE(request("view top").ok);
  const auto sets = frameSets(*surroundd);
  waitForSets(*surroundd, sets + 3);
  const auto after = request("snapshot");
  ASSERT_TRUE(after.ok);
  const auto top =
      cv::imdecode(std::vector<uchar>(after.body.begin(), after.body.end()), cv::IMREAD_COLOR);
  ASSERT_EQ(top.size(), cv::Size(320, 240));
  EXPECT_GT(cv::norm(orbit, top, cv::NORM_L1) / static_cast<double>(orbit.total() * 3), 10.0);
  // From the request to the top view settled in the outputs, beside its limits.
  waitForLog(*surroundd, "view switch: first picture");
  EXPECT_THAT(request("status").body, HasSubstr("settled"));
  EXPECT_THAT(request("status").body, HasSubstr("after the request (FMVSS 111: <= 2.0 s"));
  EXPECT_THAT(request("metrics").body,
              HasSubstr("surroundd_view_switch_seconds{picture=\"settled\"}"));
  // The live page marks the view it was switched to.
  std::smatch port;
  const std::string log = surroundd->output();
  ASSERT_TRUE(std::regex_search(log, port, std::regex("HTTP stream: http://127.0.0.1:([0-9]+)/")));
  EXPECT_THAT(testing::httpRequest(std::stoi(port[1]), "GET", "/views.json").body,
              HasSubstr(R"("active": "top")"));
  EXPECT_THAT(request("view sideways").body, HasSubstr("unknown view 'sideways'"));

  // surroundctl itself.
  testing::ChildProcess ctl({SURROUNDCTL_EXECUTABLE, "--socket", socket_.string(), "metrics"},
                            dir_ / "ctl.txt");
  EXPECT_EQ(ctl.wait(), 0);
  EXPECT_THAT(ctl.output(), HasSubstr("# TYPE surroundd_stage_seconds summary"));
  testing::ChildProcess bad({SURROUNDCTL_EXECUTABLE, "--socket", socket_.string(), "view", "x"},
                            dir_ / "bad.txt");
  EXPECT_EQ(bad.wait(), 1);
  EXPECT_THAT(bad.output(), HasSubstr("surroundctl: surroundd says: unknown view 'x'"));

  surroundd->signal(SIGTERM);
  EXPECT_EQ(surroundd->wait(), 0) << surroundd->output();
  EXPECT_THAT(surroundd->output(), HasSubstr("stop requested: finalizing outputs"));
  EXPECT_FALSE(std::filesystem::exists(socket_));  // removed on the way out
  for (const char* file : {"out/orbit.mp4", "out/mosaic.mkv"}) {
    const auto video = testing::decodeAll(dir_ / file);
    EXPECT_EQ(video.last, capture::ReadStatus::kEndOfStream) << file;
    EXPECT_GE(video.images.size(), 10u) << file;
  }
}

// The vehicle's signals through surroundctl: reverse gear brings up the rule's view at once, and
// once the gear is no longer renewed it goes back to the view the outputs had. The signals go stale
// after 2 s: the switch maps the top view on the pipeline's thread, which under ThreadSanitizer on
// a loaded machine took 0.75 s, and a shorter limit let the gear go stale before `status` was read.
TEST_F(ServiceTest, ViewRulesFollowTheVehicleSignalsAndLetGoWhenTheyGoStale) {
  auto surroundd = start(writeConfig("  - {type: video, stream: surround, path: out/orbit.mp4}",
                                     "vehicle_signals:\n  stale_after_s: 2.0\n  view_rules:\n"
                                     "    - {gear: R, view: top}\n"));
  waitForSets(*surroundd, 5);
  const auto snapshot = [&] {
    const auto reply = request("snapshot");
    EXPECT_TRUE(reply.ok) << reply.body;
    return cv::imdecode(std::vector<uchar>(reply.body.begin(), reply.body.end()), cv::IMREAD_COLOR);
  };
  const cv::Mat orbit = snapshot();
  EXPECT_THAT(request("status").body, HasSubstr("vehicle: gear unknown (none)"));

  testing::ChildProcess ctl(
      {SURROUNDCTL_EXECUTABLE, "--socket", socket_.string(), "signal", "gear=R", "speed_kmh=2"},
      dir_ / "ctl.txt");
  ASSERT_EQ(ctl.wait(), 0) << ctl.output();
  EXPECT_THAT(ctl.output(), HasSubstr("gear R, steering 0.0 deg (none), speed 2.0 km/h"));
  // Switched in the loop that took the signal, before the next frame set.
  EXPECT_THAT(surroundd->output(), HasSubstr("view rules: top (gear R -> top)"));
  EXPECT_THAT(request("status").body, HasSubstr("view rule: gear R -> top"));
  // Kept renewed past the 0.4 s transition, the pictures are the top view's.
  for (int k = 0; k < 8; ++k) {
    ASSERT_TRUE(request("signal gear=R").ok);
    std::this_thread::sleep_for(100ms);
  }
  const auto sets = frameSets(*surroundd);
  waitForSets(*surroundd, sets + 2);
  const cv::Mat top = snapshot();
  ASSERT_EQ(top.size(), orbit.size());
  EXPECT_GT(cv::norm(orbit, top, cv::NORM_L1) / static_cast<double>(orbit.total() * 3), 10.0);

  // Not renewed: stale after 2 s, and the orbit comes back.
  waitForLog(*surroundd, "view rules: orbit (no rule holds: the view chosen last)");
  EXPECT_THAT(request("status").body, HasSubstr("gear R (stale)"));
  const auto refused = request("signal gear=X");
  EXPECT_FALSE(refused.ok);
  EXPECT_THAT(refused.body, HasSubstr("signal: gear: expected P, R, N or D, got 'X'"));

  surroundd->signal(SIGTERM);
  EXPECT_EQ(surroundd->wait(), 0) << surroundd->output();
}

// The guidelines (render.guidelines: reverse, amber paths): drawn in reverse gear as the steering
// says, in a view gathered through its own LUT (top) and in one OpenGL draws (a moving orbit).
TEST_F(ServiceTest, GuidelinesFollowTheGearAndTheSteering) {
  auto surroundd =
      start(writeConfig("  - {type: video, stream: surround, view: top, path: out/top.mp4}"));
  waitForSets(*surroundd, 5);
  // Paced as a live rig: the first picture drawn by OpenGL, the top view's table made after it
  // and then taken into use.
  const std::string gathered = "the top view 320x240 is gathered from the camera frames";
  waitForLog(*surroundd, gathered);
  const std::string log = surroundd->output();
  EXPECT_LT(log.find("first picture out"), log.find(gathered));
  cv::Mat last;
  const auto amberPixels = [&] {
    waitForSets(*surroundd, frameSets(*surroundd) + 3);
    const auto reply = request("snapshot");
    EXPECT_TRUE(reply.ok) << reply.body;
    last = cv::imdecode(std::vector<uchar>(reply.body.begin(), reply.body.end()), cv::IMREAD_COLOR);
    cv::Mat amber;
    cv::inRange(last, cv::Scalar(0, 201, 247), cv::Scalar(8, 217, 255), amber);
    return cv::countNonZero(amber);
  };
  EXPECT_EQ(amberPixels(), 0);
  ASSERT_TRUE(request("signal gear=R steering_deg=300").ok);
  EXPECT_GT(amberPixels(), 100);
  const cv::Mat left = last.clone();
  ASSERT_TRUE(request("signal gear=R steering_deg=-300").ok);
  EXPECT_GT(amberPixels(), 100);
  // The paths bend the other way: the pictures differ where they are (the ground stays).
  EXPECT_GT(cv::norm(left, last, cv::NORM_L1) / 255, 100);
  ASSERT_TRUE(request("signal gear=D").ok);
  EXPECT_EQ(amberPixels(), 0);

  ASSERT_TRUE(request("view orbit").ok);
  for (int k = 0; k < 6; ++k) {  // past the 0.4 s switch, the gear kept fresh
    ASSERT_TRUE(request("signal gear=R steering_deg=100").ok);
    std::this_thread::sleep_for(100ms);
  }
  EXPECT_GT(amberPixels(), 20);
  surroundd->signal(SIGTERM);
  EXPECT_EQ(surroundd->wait(), 0) << surroundd->output();
}

TEST_F(ServiceTest, AReloadWithABadConfigIsRejectedAndAGoodOneRestartsTheOutputs) {
  const auto config = writeConfig(R"(  - {type: video, stream: mosaic, path: out/first.mp4})");
  auto surroundd = start(config);
  waitForSets(*surroundd, 5);

  // A bad config, by SIGHUP: rejected, logged, and the pipeline goes on.
  writeConfig(R"(  - {type: video, stream: mosaic, path: out/first.mp4, crf: 99})");
  const auto sets = frameSets(*surroundd);
  surroundd->signal(SIGHUP);
  waitForSets(*surroundd, sets + 10);
  EXPECT_GT(frameSets(*surroundd), sets + 9);  // the same run: its count went on
  EXPECT_THAT(surroundd->output(), HasSubstr("reload rejected"));
  EXPECT_THAT(surroundd->output(), HasSubstr("crf"));

  // The same through the socket: the client hears why.
  const auto rejected = request("reload");
  EXPECT_FALSE(rejected.ok);
  EXPECT_THAT(rejected.body, HasSubstr("config rejected, the running one goes on"));

  // A good one: the first file is finalized, the new outputs start under new names.
  writeConfig(R"(  - {type: video, stream: mosaic, path: out/first.mp4}
  - {type: snapshot, stream: mosaic, path: out/still.png, at_s: 0.1})");
  const auto reloaded = std::chrono::steady_clock::now();
  const auto accepted = request("reload");
  EXPECT_TRUE(accepted.ok) << accepted.body;
  // The reply comes before the old pipeline ends; every status after this line is the new one's.
  waitForLog(*surroundd, "reload: starting the pipeline for the new config");
  waitForSets(*surroundd, 5);
  // The new run's start-up: the gap the reload left in the pictures.
  expectFirstPictureWithin("reload", reloaded);
  surroundd->signal(SIGTERM);
  EXPECT_EQ(surroundd->wait(), 0) << surroundd->output();
  const auto first = testing::decodeAll(dir_ / "out/first.mp4");
  EXPECT_EQ(first.last, capture::ReadStatus::kEndOfStream);
  EXPECT_GE(first.images.size(), 15u);
  const auto second = testing::decodeAll(dir_ / "out/first-1.mp4");
  EXPECT_EQ(second.last, capture::ReadStatus::kEndOfStream);
  EXPECT_GE(second.images.size(), 5u);
  EXPECT_FALSE(cv::imread((dir_ / "out/still.png").string()).empty());  // the newest picture
  EXPECT_THAT(surroundd->output(), HasSubstr("reload: starting the pipeline for the new config"));
}

TEST_F(ServiceTest, AStalledOutputStageStopsTheWatchdogPings) {
  // The output's file is a FIFO nobody reads: once its buffer is full, writing blocks, like a
  // storage device that hangs.
  std::filesystem::create_directories(dir_ / "out");
  ASSERT_EQ(::mkfifo((dir_ / "out/stall.mkv.part").c_str(), 0600), 0);
  testing::NotifySocket notify(dir_ / "notify");
  auto surroundd =
      start(writeConfig(R"(  - {type: video, stream: mosaic, path: out/stall.mkv, crf: 0})"),
            {"NOTIFY_SOCKET=" + (dir_ / "notify").string(), "WATCHDOG_USEC=200000"});
  // Opening the read end lets the daemon's open() return; nothing is ever read.
  const int reader = ::open((dir_ / "out/stall.mkv.part").c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(reader, 0);
  // Until READY=1 and the first ping (however slowly it starts: CI load, TSan), then until the
  // pings have stopped for 3 s (several 200 ms watchdog periods); at most 60 s in all.
  std::vector<testing::NotifySocket::Message> messages;
  const auto isPing = [](const auto& m) { return m.text == "WATCHDOG=1"; };
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  bool stopped = false;
  while (!stopped && std::chrono::steady_clock::now() < deadline && surroundd->running()) {
    if (auto message = notify.receive()) messages.push_back(std::move(*message));
    const auto lastPing = std::ranges::find_if(messages.rbegin(), messages.rend(), isPing);
    stopped = lastPing != messages.rend() && std::chrono::steady_clock::now() - lastPing->at > 3s;
  }
  ASSERT_TRUE(surroundd->running()) << surroundd->output();
  ::close(reader);
  ASSERT_FALSE(messages.empty());
  EXPECT_EQ(messages.front().text, "READY=1");
  EXPECT_GE(std::ranges::count_if(messages, isPing), 1);
  EXPECT_TRUE(stopped) << "the watchdog pings went on while the output stage was stalled";
}

// (A short name: the notify socket's path, in a folder named after the test, must fit in 108
// bytes.)
TEST_F(ServiceTest, DegradedWhileNoOutputWorks) {
  // Issue 18.3: a recorder whose only output had failed kept feeding the watchdog. Its folder is
  // taken away (a file stands in its place, so every new segment fails to open, as on a full
  // disk), then given back.
  testing::NotifySocket notify(dir_ / "notify");
  auto surroundd = start(
      writeConfig(R"(  - {type: video, stream: mosaic, path: out/drive.mkv, segment_s: 0.5})"),
      {"NOTIFY_SOCKET=" + (dir_ / "notify").string(), "WATCHDOG_USEC=200000"});
  std::vector<testing::NotifySocket::Message> messages;
  const auto isPing = [](const auto& m) { return m.text == "WATCHDOG=1"; };
  const auto isDegraded = [](const auto& m) {
    return m.text.starts_with("STATUS=degraded: every output has failed");
  };
  // Reads until `done` holds, at most 60 s (however slowly it runs: CI load, sanitizers).
  const auto readUntil = [&](const std::function<bool()>& done) {
    for (const auto deadline = std::chrono::steady_clock::now() + 60s;
         !done() && std::chrono::steady_clock::now() < deadline && surroundd->running();) {
      if (auto message = notify.receive()) messages.push_back(std::move(*message));
    }
    return done();
  };
  ASSERT_TRUE(readUntil([&] { return std::ranges::any_of(messages, isPing); }))
      << surroundd->output();

  std::filesystem::rename(dir_ / "out", dir_ / "out-taken");
  dir_.write("out", "not a folder");
  const auto taken = messages.size();
  const auto since = [&](std::size_t from, const auto& what) {
    return std::ranges::any_of(messages.begin() + static_cast<std::ptrdiff_t>(from), messages.end(),
                               what);
  };
  // Degraded, and then no ping for 3 s (fifteen 200 ms watchdog periods).
  const bool quiet = readUntil([&] {
    if (!since(taken, isDegraded)) return false;
    const auto lastPing = std::ranges::find_if(messages.rbegin(), messages.rend(), isPing);
    return std::chrono::steady_clock::now() - lastPing->at > 3s;
  });
  ASSERT_TRUE(surroundd->running()) << surroundd->output();
  EXPECT_TRUE(quiet) << "no degraded status, or the pings went on: " << surroundd->output();
  EXPECT_THAT(surroundd->output(), HasSubstr("output still failing"));

  // The folder is back: the next retry opens the output again and the pings resume.
  std::filesystem::remove(dir_ / "out");
  const auto back = messages.size();
  EXPECT_TRUE(readUntil([&] { return since(back, isPing); })) << surroundd->output();
  EXPECT_THAT(surroundd->output(), HasSubstr("works again"));
  surroundd->signal(SIGTERM);
  EXPECT_EQ(surroundd->wait(), 1) << "an output failed in this run: " << surroundd->output();
  EXPECT_FALSE(std::filesystem::is_empty(dir_ / "out"));
}

}  // namespace
}  // namespace surroundd::daemon
