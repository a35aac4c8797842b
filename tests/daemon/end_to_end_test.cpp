// surroundd as a user runs it: replay a generated recording, decode the MP4 it wrote and compare it
// with the mosaic of the source frames; stop it with SIGTERM; give it a bad config.

#include <thread>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "capture/file_source.hpp"
#include "common/work_pool.hpp"
#include "daemon/config/panorama_setup.hpp"
#include "daemon/config/rig_yaml.hpp"
#include "processing/colour/poisson_correction.hpp"
#include "processing/stitch/stitcher.hpp"
#include "render/egl_context.hpp"
#include "render/mosaic.hpp"
#include "render/surround_view.hpp"
#include "tests/support/child_process.hpp"
#include "tests/support/stream_receiver.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

std::filesystem::path recording() {
  return std::filesystem::path(SURROUNDD_FIXTURE_DIR) / "synth_small";
}
// NOLINTNEXTLINE(cert-err58-cpp): cv::Size stores two ints; its constructor throws nothing.
const cv::Size kOutputSize(640, 360);

std::filesystem::path writeConfig(const testing::TempDir& dir, std::string_view extra = "") {
  return dir.write("config.yaml", fmt::format(R"(rig: {{file: {}}}
render: {{width_px: {}, height_px: {}}}
outputs:
  - {{type: video, path: out/mosaic.mp4, crf: 16}}
  - {{type: snapshot, path: out/mosaic.png, at_s: 0.5}}
{})",
                                              (recording() / "rig.yaml").string(),
                                              kOutputSize.width, kOutputSize.height, extra));
}

// The calibration-drift watch: synth_seams replayed with the calibration that rendered it, then
// with its front camera's turned by 2 degrees (as a knocked camera looks against the calibration
// it had): the front camera alone is said to drift, with the ground under both its seams 13-14 cm
// apart (4.1 m from the camera: 4.1 m x 2 degrees = 14 cm).
TEST(EndToEnd, TheCalibrationWatchNamesTheCameraThatWasTurned) {
  const auto seams = std::filesystem::path(SURROUNDD_FIXTURE_DIR) / "synth_seams";
  std::string rig = testing::fileBytes(seams / "rig.yaml");
  for (const std::string name : {"front", "right", "back", "left"}) {
    const std::string source = "file: " + name + ".mkv";
    rig.replace(rig.find(source), source.size(), "file: " + (seams / (name + ".mkv")).string());
  }
  for (const bool turned : {false, true}) {
    SCOPED_TRACE(turned ? "front turned by 2 degrees" : "the true calibration");
    const testing::TempDir dir;
    std::string text = rig;
    if (turned) {
      const std::string yaw = "yaw_deg: 0,";  // the front camera's, the first
      text.replace(text.find(yaw), yaw.size(), "yaw_deg: 2,");
    }
    dir.write("rig.yaml", text);
    const auto config = dir.write("config.yaml", R"(rig: {file: rig.yaml}
panorama: {width_px: 1024, height_px: 512, cache_dir: lut-cache}
calibration_watch: {interval_s: 0.2, threshold_cm: 5}
outputs:
  - {type: snapshot, stream: panorama, path: out/panorama.png, at_s: 0.5}
)");
    testing::ChildProcess surroundd(
        {SURROUNDD_EXECUTABLE, "--config", config.string(), "--pacing", "as_fast_as_possible"},
        dir / "log.txt");
    ASSERT_EQ(surroundd.wait(), 0) << surroundd.output();
    const std::string log = surroundd.output();
    if (!turned) {
      EXPECT_THAT(log, ::testing::Not(::testing::HasSubstr("drifting"))) << log;
      continue;
    }
    EXPECT_THAT(log, ::testing::ContainsRegex(
                         "calibration watch: camera 'front' is drifting: the ground under its "
                         "seams is 1[34]\\.[0-9] cm at front/right, 1[34]\\.[0-9] cm at "
                         "left/front apart"))
        << log;
    for (const std::string other : {"right", "back", "left"}) {
      EXPECT_THAT(log, ::testing::Not(::testing::HasSubstr("camera '" + other + "' is drifting")));
    }
  }
}

TEST(EndToEnd, MosaicVideoMatchesTheSourceFrames) {
  const testing::TempDir dir;
  testing::ChildProcess surroundd({SURROUNDD_EXECUTABLE, "--config", writeConfig(dir).string(),
                                   "--pacing", "as_fast_as_possible"},
                                  dir / "log.txt");
  ASSERT_EQ(surroundd.wait(), 0) << surroundd.output();

  const auto rig = daemon::loadRigFile(recording() / "rig.yaml");
  std::vector<std::string> names;
  std::vector<std::vector<cv::Mat>> sources;
  for (const auto& camera : rig) {
    names.push_back(camera.calibration.name);
    sources.push_back(testing::decodeAll(camera.replayedFile()->path).images);
  }
  const auto video = testing::decodeAll(dir / "out/mosaic.mp4").images;
  ASSERT_EQ(video.size(),
            sources[0].size());  // one frame set per frame: the recording drops nothing

  const render::Mosaic mosaic(kOutputSize, names);
  cv::Mat expected(kOutputSize, CV_8UC3);
  for (const std::size_t k : {std::size_t{0}, video.size() / 2, video.size() - 1}) {
    std::vector<const cv::Mat*> frames;
    frames.reserve(sources.size());
    for (const auto& camera : sources) frames.push_back(&camera[k]);
    mosaic.compose(frames, expected);
    EXPECT_GE(cv::PSNR(expected, video[k]), 35.0) << "frame " << k;
  }

  const cv::Mat snapshot = cv::imread((dir / "out/mosaic.png").string());
  EXPECT_EQ(snapshot.size(), kOutputSize);
  for (const auto& entry : std::filesystem::directory_iterator(dir / "out")) {
    EXPECT_NE(entry.path().extension(), ".part") << entry.path();
  }
  EXPECT_THAT(surroundd.output(), HasSubstr("wrote video"));
}

// The panorama output: the video shows the colour-corrected stitch of the source frames; the LUT is
// built on the first run, loaded on the next, and rebuilt when its cache file is damaged.
// The recording of a config, and the panorama the daemon makes of each of its frame sets.
struct Replay {
  explicit Replay(daemon::Config loaded)
      : config(std::move(loaded)),
        rig(daemon::rigOf(config, pool)),
        lut(daemon::obtainPanoramaLut(config, rig, pool)) {
    for (const auto& camera : config.cameras) {
      auto decoded = testing::decodeAll(camera.replayedFile()->path);
      sources.push_back(std::move(decoded.images));
      timestamps.push_back(std::move(decoded.timestamps));
    }
  }
  std::size_t frameSets() const { return sources[0].size(); }  // the recording drops nothing
  double streamTime(std::size_t k) const {
    return std::chrono::duration<double>(timestamps[0][k] - timestamps[0][0]).count();
  }
  // Stitched and colour-corrected with the config's correction (Poisson by default), solved for
  // this frame set on its own.
  cv::Mat panorama(std::size_t k) const {
    std::vector<cv::Mat> frames;
    for (const auto& camera : sources) frames.push_back(camera[k]);
    processing::Stitcher stitcher(lut, pool);
    cv::Mat stitched;
    stitcher.stitch(frames, stitched);
    processing::PoissonColourCorrection correction(rig, daemon::panoramaSettings(config), lut,
                                                   config.colour.poisson, pool);
    correction.update(frames);
    correction.apply(stitched);
    return stitched;
  }

  daemon::Config config;
  mutable WorkPool pool{2};
  processing::Rig rig;
  processing::PanoramaLut lut;
  std::vector<std::vector<cv::Mat>> sources;
  std::vector<std::vector<capture::Timestamp>> timestamps;
};

TEST(EndToEnd, PanoramaVideoMatchesTheStitchedSourceFramesAndTheLutIsCached) {
  const testing::TempDir dir;
  const auto config = dir.write("config.yaml", fmt::format(R"(rig: {{file: {}}}
capture: {{pacing: as_fast_as_possible}}
pipeline: {{threads: 2}}
panorama: {{width_px: 512, height_px: 256, cache_dir: lut-cache}}
outputs:
  - {{type: video, stream: panorama, path: out/panorama.mp4, crf: 12}}
  - {{type: snapshot, stream: panorama, path: out/panorama.png, at_s: 0.5}}
)",
                                                           (recording() / "rig.yaml").string()));
  const auto run = [&](std::string_view expectedLog) {
    testing::ChildProcess surroundd({SURROUNDD_EXECUTABLE, "--config", config.string()},
                                    dir / "log.txt");
    EXPECT_EQ(surroundd.wait(), 0) << surroundd.output();
    EXPECT_THAT(surroundd.output(), HasSubstr(expectedLog));
  };
  run("panorama LUT 512x256 (bowl projection): building");
  run("panorama LUT 512x256: loaded");
  const auto cached = *std::filesystem::directory_iterator(dir / "lut-cache");
  std::filesystem::resize_file(cached.path(), 1000);
  run("is corrupt (checksum mismatch); rebuilding");

  const Replay replay(daemon::loadConfig(config));
  const auto video = testing::decodeAll(dir / "out/panorama.mp4").images;
  ASSERT_EQ(video.size(), replay.frameSets());
  for (const std::size_t k : {std::size_t{0}, video.size() - 1}) {
    EXPECT_GE(cv::PSNR(replay.panorama(k), video[k]), 35.0) << "frame " << k;
  }
  EXPECT_EQ(cv::imread((dir / "out/panorama.png").string()).size(), replay.lut.size);
}

// The surround outputs: an orbit video with a picture for every frame set (the read-back of the
// last one included), and snapshots of other views, each the scene rendered from the panorama of
// its frame set (or for a view that does not move, gathered through its own LUT).
TEST(EndToEnd, SurroundOutputsShowTheRenderedPanoramaOfEachFrameSet) {
  const testing::TempDir dir;
  const auto config = dir.write("config.yaml", fmt::format(R"(rig: {{file: {}}}
capture: {{pacing: as_fast_as_possible}}
pipeline: {{threads: 2}}
panorama: {{width_px: 512, height_px: 256, cache_dir: lut-cache}}
render: {{width_px: 320, height_px: 240, view: orbit}}
outputs:
  - {{type: video, stream: surround, path: out/orbit.mp4, crf: 10, pixel_format: yuv444p}}
  - {{type: snapshot, stream: surround, view: top, path: out/top.png, at_s: 0.52}}
  - {{type: snapshot, stream: surround, view: 360, path: out/360.png, at_s: 1000}}
)",
                                                           (recording() / "rig.yaml").string()));
  testing::ChildProcess surroundd({SURROUNDD_EXECUTABLE, "--config", config.string()},
                                  dir / "log.txt");
  ASSERT_EQ(surroundd.wait(), 0) << surroundd.output();
  EXPECT_THAT(surroundd.output(), HasSubstr("render: "));

  const daemon::Config loaded = daemon::loadConfig(config);
  const Replay replay(loaded);
  const render::EglContext context;
  render::SurroundScene scene(
      processing::buildSurroundMesh(daemon::meshSettings(loaded),
                                    daemon::panoramaSettings(loaded).geometry),
      daemon::panoramaSettings(loaded).geometry, loaded.car(), replay.lut.cameraSizes[0]);
  render::ViewSettings cutting = loaded.render.views;  // the reference switches views at once
  cutting.transitionS = 0;
  render::SurroundView view(scene, {320, 240}, render::ViewKind::kOrbit, cutting);
  const auto rendered = [&](std::size_t k, render::ViewKind kind) {
    scene.uploadPanorama(replay.panorama(k));
    view.setView(kind);
    view.draw(replay.streamTime(k));
    return view.collect().clone();
  };

  const auto video = testing::decodeAll(dir / "out/orbit.mp4").images;
  ASSERT_EQ(video.size(), replay.frameSets());
  for (const std::size_t k : {std::size_t{0}, video.size() / 2, video.size() - 1}) {
    EXPECT_GE(cv::PSNR(rendered(k, render::ViewKind::kOrbit), video[k]), 35.0) << "frame " << k;
  }
  std::size_t snapshotAt = 0;  // the first frame set at or after 0.52 s (between two frames)
  while (replay.streamTime(snapshotAt) < 0.52) ++snapshotAt;
  // The top view does not move, so it is gathered through its own LUT: a little sharper than the
  // render, which blurs twice (tests/render/view_lut_test.cpp).
  EXPECT_THAT(surroundd.output(), HasSubstr("the top view 320x240 is gathered from the camera"));
  EXPECT_GE(cv::PSNR(rendered(snapshotAt, render::ViewKind::kTop),
                     cv::imread((dir / "out/top.png").string())),
            36.0);
  // Asked for after the end: the last frame set's picture.
  EXPECT_GE(cv::PSNR(rendered(replay.frameSets() - 1, render::ViewKind::kPanorama360),
                     cv::imread((dir / "out/360.png").string())),
            40.0);

  // The same rig with other render settings and outputs; returns the daemon's output.
  const auto runWith = [&](const std::string& name, const std::string& render,
                           const std::string& outputs) {
    const auto other = dir.write(name + ".yaml",
                                 fmt::format(R"(rig: {{file: {}}}
capture: {{pacing: as_fast_as_possible}}
pipeline: {{threads: 2}}
panorama: {{width_px: 512, height_px: 256, cache_dir: lut-cache}}
render: {{width_px: 320, height_px: 240{}}}
outputs:
{})",
                                             (recording() / "rig.yaml").string(), render, outputs));
    testing::ChildProcess run({SURROUNDD_EXECUTABLE, "--config", other.string()},
                              dir / (name + "-log.txt"));
    EXPECT_EQ(run.wait(), 0) << run.output();
    return run.output();
  };
  // With render.view_lut off the top view is rendered like the views that move.
  EXPECT_THAT(
      runWith("rendered", ", view_lut: false",
              "  - {type: snapshot, stream: surround, view: top, path: out/top-rendered.png, "
              "at_s: 0.52}"),
      Not(HasSubstr("gathered from the camera")));
  EXPECT_GE(cv::PSNR(rendered(snapshotAt, render::ViewKind::kTop),
                     cv::imread((dir / "out/top-rendered.png").string())),
            40.0);
  // With every output's view gathered through its own LUT no panorama is made; the picture asked
  // for after the end is still the last frame set's.
  runWith("gathered", "",
          "  - {type: snapshot, stream: surround, view: top, path: out/top-gathered.png, at_s: "
          "0.52}\n"
          "  - {type: snapshot, stream: surround, view: 360, path: out/360-gathered.png, at_s: "
          "1000}");
  EXPECT_GE(cv::PSNR(rendered(snapshotAt, render::ViewKind::kTop),
                     cv::imread((dir / "out/top-gathered.png").string())),
            36.0);
  EXPECT_GE(cv::PSNR(rendered(replay.frameSets() - 1, render::ViewKind::kPanorama360),
                     cv::imread((dir / "out/360-gathered.png").string())),
            36.0);

  // With a still eye the orbit and split views do not move either, and are gathered too; the
  // split view's camera half is the first camera's own picture, scaled as the renderer scales it.
  const std::string still =
      runWith("still", ", orbit_period_s: 0, orbit_start_deg: 135",
              "  - {type: snapshot, stream: surround, view: split, path: out/split-still.png, "
              "at_s: 0.52}\n"
              "  - {type: snapshot, stream: surround, view: orbit, path: out/orbit-still.png, "
              "at_s: 0.52}");
  EXPECT_THAT(still, HasSubstr("the split view 320x240 is gathered from the camera"));
  EXPECT_THAT(still, HasSubstr("the orbit view 320x240 is gathered from the camera"));
  render::ViewSettings stillEye = cutting;
  stillEye.orbitPeriodS = 0;
  stillEye.orbitStartDeg = 135;
  render::SurroundView stillView(scene, {320, 240}, render::ViewKind::kSplit, stillEye);
  scene.uploadPanorama(replay.panorama(snapshotAt));
  scene.uploadCamera(replay.sources[0][snapshotAt]);
  stillView.draw(0);
  const cv::Mat split = stillView.collect().clone();
  const cv::Mat splitGathered = cv::imread((dir / "out/split-still.png").string());
  EXPECT_GE(cv::PSNR(split, splitGathered), 36.0);
  const cv::Rect cameraArea = *stillView.cameraArea();
  EXPECT_GE(cv::PSNR(split(cameraArea), splitGathered(cameraArea)), 40.0);
  stillView.setView(render::ViewKind::kOrbit);
  stillView.draw(0);
  EXPECT_GE(cv::PSNR(stillView.collect(), cv::imread((dir / "out/orbit-still.png").string())),
            36.0);
}

// A mosaic snapshot asked for after the end, with no other mosaic output: the last frame set's
// mosaic, not an empty canvas.
TEST(EndToEnd, AMosaicSnapshotAfterTheEndShowsTheLastFrameSet) {
  const testing::TempDir dir;
  const auto config = dir.write("config.yaml", fmt::format(R"(rig: {{file: {}}}
capture: {{pacing: as_fast_as_possible}}
render: {{width_px: {}, height_px: {}}}
outputs:
  - {{type: snapshot, stream: mosaic, path: out/last.png, at_s: 1000}}
)",
                                                           (recording() / "rig.yaml").string(),
                                                           kOutputSize.width, kOutputSize.height));
  testing::ChildProcess surroundd({SURROUNDD_EXECUTABLE, "--config", config.string()},
                                  dir / "log.txt");
  ASSERT_EQ(surroundd.wait(), 0) << surroundd.output();
  const auto rig = daemon::loadRigFile(recording() / "rig.yaml");
  std::vector<std::string> names;
  std::vector<cv::Mat> last;
  for (const auto& camera : rig) {
    names.push_back(camera.calibration.name);
    last.push_back(testing::decodeAll(camera.replayedFile()->path).images.back());
  }
  std::vector<const cv::Mat*> frames;
  frames.reserve(last.size());
  for (const auto& image : last) frames.push_back(&image);
  cv::Mat expected(kOutputSize, CV_8UC3);
  render::Mosaic(kOutputSize, names).compose(frames, expected);
  EXPECT_GE(cv::PSNR(expected, cv::imread((dir / "out/last.png").string())), 40.0);
}

TEST(EndToEnd, SigtermLeavesAPlayableFile) {
  const testing::TempDir dir;
  testing::ChildProcess surroundd({SURROUNDD_EXECUTABLE, "--config", writeConfig(dir).string()},
                                  dir / "log.txt");
  // Once the cameras are open (logged) the signal handlers are in place; then stop mid-recording.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (surroundd.output().find("camera 'left'") == std::string::npos &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  surroundd.signal(SIGTERM);
  ASSERT_EQ(surroundd.wait(), 0) << surroundd.output();
  const auto frames = testing::decodeAll(dir / "out/mosaic.mp4").images;
  EXPECT_GE(frames.size(), 1u);
  EXPECT_FALSE(std::filesystem::exists(dir / "out/mosaic.mp4.part"));
  EXPECT_TRUE(
      std::filesystem::exists(dir / "out/mosaic.png"));  // the last frame, as the run was short
}

TEST(EndToEnd, BadConfigOpensNothing) {
  const testing::TempDir dir;
  testing::ChildProcess surroundd(
      {SURROUNDD_EXECUTABLE, "--config", writeConfig(dir, "capture: {queue_frames: 0}").string()},
      dir / "log.txt");
  EXPECT_EQ(surroundd.wait(), 2);
  EXPECT_THAT(surroundd.output(),
              HasSubstr("config.yaml:6:25: capture.queue_frames: expected a whole number"));
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

// A live rig whose camera is not plugged in: one message naming the camera and its device path.
TEST(EndToEnd, ALiveCameraThatIsNotThereIsNamed) {
  const testing::TempDir dir;
  const auto rig = daemon::loadRigFile(recording() / "rig.yaml");
  std::vector<daemon::RigCamera> live(rig.begin(), rig.end());
  for (auto& camera : live) {
    capture::V4l2Settings device;
    device.device = "/dev/v4l/by-id/usb-surroundd-test-" + camera.calibration.name;
    device.size = camera.calibration.intrinsics.imageSize;
    camera.source = device;
  }
  daemon::writeRigFile(dir / "rig.yaml", live, "live rig");
  const auto config = dir.write("config.yaml", R"(rig: {file: rig.yaml}
outputs:
  - {type: video, stream: mosaic, path: out/mosaic.mp4}
)");
  testing::ChildProcess surroundd({SURROUNDD_EXECUTABLE, "--config", config.string()},
                                  dir / "log.txt");
  EXPECT_EQ(surroundd.wait(), 1);
  EXPECT_THAT(surroundd.output(),
              HasSubstr("camera 'front': /dev/v4l/by-id/usb-surroundd-test-front: cannot open: No "
                        "such file or directory"));
  // None is there, and all are tried at once: the first in the rig is the one named.
  for (const char* other : {"right", "back", "left"}) {
    EXPECT_THAT(surroundd.output(), Not(HasSubstr(std::string("usb-surroundd-test-") + other)));
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "out/mosaic.mp4"));
}

TEST(EndToEnd, UnknownOptionIsAUsageError) {
  const testing::TempDir dir;
  testing::ChildProcess surroundd({SURROUNDD_EXECUTABLE, "--confg", "x.yaml"}, dir / "log.txt");
  EXPECT_EQ(surroundd.wait(), 2);
  EXPECT_THAT(surroundd.output(), HasSubstr("unknown option '--confg'"));
}

// The network output: MPEG-TS over UDP on loopback, decoded by FFmpeg as a viewer would, shows
// the same pictures as the video file of the same view (itself checked against renders above).
TEST(EndToEnd, TheNetworkStreamDecodesToTheRenderedFrames) {
  const testing::TempDir dir;
  const int port = testing::freeUdpPort();
  const auto config =
      dir.write("config.yaml", fmt::format(R"(rig: {{file: {}}}
capture: {{pacing: realtime}}
pipeline: {{threads: 2}}
panorama: {{width_px: 512, height_px: 256, cache_dir: lut-cache}}
render: {{width_px: 320, height_px: 240, view: orbit}}
outputs:
  - {{type: network, stream: surround, url: "udp://127.0.0.1:{}", crf: 18}}
  - {{type: video, stream: surround, path: out/orbit.mkv, crf: 0, pixel_format: yuv444p}}
)",
                                           (recording() / "rig.yaml").string(), port));
  testing::StreamReceiver receiver(port, std::chrono::seconds(3));
  testing::ChildProcess surroundd({SURROUNDD_EXECUTABLE, "--config", config.string()},
                                  dir / "log.txt");
  ASSERT_EQ(surroundd.wait(), 0) << surroundd.output();
  EXPECT_THAT(surroundd.output(), HasSubstr(fmt::format("wrote stream udp://127.0.0.1:{}", port)));
  const auto file = testing::decodeAll(dir / "out/orbit.mkv").images;
  const auto received = receiver.pictures();
  ASSERT_EQ(received.size(), file.size()) << receiver.error();
  for (std::size_t k = 0; k < file.size(); ++k) {
    EXPECT_GE(cv::PSNR(received[k].bgr, file[k]), 32.0) << "frame " << k;
  }
}

}  // namespace
}  // namespace surroundd
