// surround-calibrate mask as a user runs it on a recording's config: each camera's -body.png is
// the daemon's own mask pixel for pixel, its overlay changes the first frame exactly where the mask
// is (tinted half red; the outline and the label aside), a camera's replacing polygon is exactly
// that polygon, and bad input exits 2 naming what was wrong.

#include <functional>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <yaml-cpp/yaml.h>

#include "capture/file_source.hpp"
#include "common/work_pool.hpp"
#include "daemon/config/config.hpp"
#include "daemon/config/panorama_setup.hpp"
#include "tests/calibration/calibrate_run.hpp"
#include "tests/support/child_process.hpp"
#include "tests/support/temp_dir.hpp"

namespace surroundd::calibration::testing {
namespace {

using surroundd::testing::TempDir;
using ::testing::HasSubstr;

// The paper rig: roof cameras at 1.9 m, 0.3 m from the centre, pitched 25 degrees down, so a
// 1.5 m roof fills the bottom of every picture.
const std::filesystem::path kRecording =
    std::filesystem::path(SURROUNDD_FIXTURE_DIR) / "synth_small";
constexpr std::string_view kVehicle = "vehicle: {length_m: 4.5, width_m: 1.85, height_m: 1.5}\n";

// The recording's rig in `dir` (sources made absolute), edited by `edit`.
std::filesystem::path writeRig(const TempDir& dir, const std::function<void(YAML::Node&)>& edit) {
  YAML::Node rig = YAML::LoadFile((kRecording / "rig.yaml").string());
  for (YAML::Node camera : rig["cameras"]) {
    camera["source"]["file"] = (kRecording / camera["source"]["file"].as<std::string>()).string();
  }
  edit(rig);
  YAML::Emitter out;
  out << rig;
  return dir.write("rig.yaml", out.c_str());
}

std::filesystem::path writeConfig(const TempDir& dir, const std::filesystem::path& rig,
                                  std::string_view vehicle) {
  return dir.write("config.yaml",
                   fmt::format("rig: {{file: {}}}\n{}outputs:\n  - {{type: snapshot, path: "
                               "out/panorama.png}}\n",
                               rig.string(), vehicle));
}

cv::Mat firstFrame(const daemon::RigCamera& camera) {
  auto settings = *camera.replayedFile();
  settings.pacing = capture::Pacing::kAsFastAsPossible;
  capture::FileSource source(camera.calibration.name, settings);
  capture::Frame frame;
  frame.image.create(source.frameSize(), CV_8UC3);
  EXPECT_EQ(source.read(frame), capture::ReadStatus::kFrame);
  return frame.image;
}

cv::Mat readMask(const std::filesystem::path& file) {
  const cv::Mat mask = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(mask.type(), CV_8U) << file;
  return mask;
}

void expectSameMask(const cv::Mat& written, const cv::Mat& expected, const std::string& what) {
  ASSERT_EQ(written.size(), expected.size()) << what;
  EXPECT_EQ(cv::countNonZero(written != expected), 0) << what;
}

// `overlay` against the `picture` it was drawn on: unchanged away from the mask but for the label
// (a box in one corner), and inside it, away from the outline, `picture` blended half with red.
// The 2-px outline is drawn in yellow along the mask's edge.
void expectOverlay(const cv::Mat& overlay, const cv::Mat& picture, const cv::Mat& mask,
                   const std::string& camera) {
  SCOPED_TRACE(camera);
  ASSERT_EQ(overlay.size(), picture.size());
  ASSERT_EQ(overlay.type(), CV_8UC3);
  cv::Mat difference;
  cv::absdiff(overlay, picture, difference);
  cv::Mat changed;
  cv::transform(difference, changed, cv::Matx13f(1, 1, 1));
  changed = changed > 0;
  // The outline is 2 px wide on the edge; 3 px either side leaves it out.
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, {7, 7});
  cv::Mat grown, shrunk;
  cv::dilate(mask, grown, kernel);
  cv::erode(mask, shrunk, kernel, {-1, -1}, 1, cv::BORDER_CONSTANT, cv::Scalar(0));

  const cv::Rect label = cv::boundingRect(changed & ~grown);
  const cv::Rect whole({}, picture.size());
  ASSERT_GT(label.area(), 0) << "no label";
  EXPECT_LT(label.area(), whole.area() / 4);
  EXPECT_TRUE((label.x == 0 || label.br().x == whole.width) &&
              (label.y == 0 || label.br().y == whole.height))
      << "what changed outside the mask is not a box in a corner: " << label;

  cv::Mat inside = shrunk.clone();
  inside(label).setTo(0);
  cv::Mat tinted;
  cv::addWeighted(picture, 0.5, cv::Mat(picture.size(), CV_8UC3, cv::Scalar(0, 0, 255)), 0.5, 0,
                  tinted);
  cv::Mat offTint;
  cv::absdiff(overlay, tinted, offTint);
  cv::transform(offTint, offTint, cv::Matx13f(1, 1, 1));
  EXPECT_EQ(cv::countNonZero((offTint > 3) & inside), 0) << "inside the mask, not tinted red";
  EXPECT_EQ(cv::countNonZero(~changed & inside), 0) << "inside the mask, unchanged";

  if (cv::countNonZero(mask) > 0) {
    cv::Mat yellow;
    cv::inRange(overlay, cv::Scalar(0, 255, 255), cv::Scalar(0, 255, 255), yellow);
    EXPECT_GT(cv::countNonZero(yellow & grown & ~shrunk), 0) << "no outline";
    EXPECT_EQ(cv::countNonZero(yellow & ~grown), 0) << "an outline away from the mask";
  }
}

TEST(MaskCli, WritesTheDaemonsMaskAndAnOverlayForEachCamera) {
  const TempDir dir;
  const auto config = writeConfig(dir, kRecording / "rig.yaml", kVehicle);
  const CalibrateRun run =
      calibrate(dir, {"mask", "--config", config.string(), "--out", (dir / "masks").string()});
  ASSERT_EQ(run.status, 0) << run.output;

  const daemon::Config loaded = daemon::loadConfig(config);
  ASSERT_EQ(loaded.cameras.size(), 4u);
  WorkPool pool(1);
  for (std::size_t c = 0; c < loaded.cameras.size(); ++c) {
    const std::string& name = loaded.cameras[c].calibration.name;
    const cv::Mat expected = daemon::bodyMaskOf(loaded, c, pool);
    ASSERT_FALSE(expected.empty()) << name << ": the roof is in view";
    ASSERT_LT(cv::countNonZero(expected), static_cast<int>(expected.total())) << name;
    const auto body = dir / "masks" / (name + "-body.png");
    const auto overlayFile = dir / "masks" / (name + "-mask-overlay.png");
    const cv::Mat mask = readMask(body);
    expectSameMask(mask, expected, name);
    expectOverlay(cv::imread(overlayFile.string(), cv::IMREAD_UNCHANGED),
                  firstFrame(loaded.cameras[c]), expected, name);
    const double share = 100.0 * cv::countNonZero(expected) / static_cast<double>(expected.total());
    EXPECT_THAT(run.output, HasSubstr(fmt::format("{}: {:.1f} % masked (computed from vehicle:)",
                                                  name, share)));
    EXPECT_THAT(run.output, HasSubstr(body.string()));
    EXPECT_THAT(run.output, HasSubstr(overlayFile.string()));
    EXPECT_THAT(run.output, HasSubstr(fmt::format("- name: {}\n    body_mask: {{file: {}, mode: "
                                                  "replace}}",
                                                  name, body.string())));
  }
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir / "masks")) {
    EXPECT_EQ(entry.path().extension(), ".png") << entry.path();  // no .part left
    ++files;
  }
  EXPECT_EQ(files, 8u);
}

TEST(MaskCli, AReplacingPolygonIsExactlyThatPolygon) {
  const TempDir dir;
  const auto rig = writeRig(dir, [](YAML::Node& yaml) {
    yaml["cameras"][1]["body_mask"] =
        YAML::Load("{polygon: [[40, 90], [280, 80], [250, 170], [60, 160]], mode: replace}");
  });
  const auto config = writeConfig(dir, rig, kVehicle);
  const CalibrateRun run = calibrate(dir, {"mask", "--config", config.string(), "--out",
                                           (dir / "masks").string(), "--camera", "right"});
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr("right: "));
  EXPECT_THAT(run.output, HasSubstr("(polygon)"));
  EXPECT_THAT(run.output, ::testing::Not(HasSubstr("front")));
  EXPECT_FALSE(std::filesystem::exists(dir / "masks" / "front-body.png"));

  const daemon::Config loaded = daemon::loadConfig(config);
  cv::Mat polygon(loaded.cameras[1].calibration.intrinsics.imageSize, CV_8U, cv::Scalar(0));
  cv::fillPoly(polygon,
               std::vector{std::vector<cv::Point>{{40, 90}, {280, 80}, {250, 170}, {60, 160}}},
               cv::Scalar(255));
  const cv::Mat mask = readMask(dir / "masks" / "right-body.png");
  expectSameMask(mask, polygon, "right");
  expectOverlay(cv::imread((dir / "masks" / "right-mask-overlay.png").string()),
                firstFrame(loaded.cameras[1]), polygon, "right");
}

TEST(MaskCli, WithoutAVehicleNothingIsMaskedAndItSaysSo) {
  const TempDir dir;
  const auto config = writeConfig(dir, kRecording / "rig.yaml", "");
  const CalibrateRun run = calibrate(dir, {"mask", "--config", config.string(), "--out",
                                           (dir / "masks").string(), "--camera", "back"});
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr("no vehicle is configured"));
  EXPECT_THAT(run.output, HasSubstr("back: 0.0 % masked"));
  const cv::Mat mask = readMask(dir / "masks" / "back-body.png");
  ASSERT_FALSE(mask.empty());
  EXPECT_EQ(cv::countNonZero(mask), 0);
  const daemon::Config loaded = daemon::loadConfig(config);
  expectOverlay(cv::imread((dir / "masks" / "back-mask-overlay.png").string()),
                firstFrame(loaded.cameras[2]), mask, "back");
}

TEST(MaskCli, ALiveCameraIsDrawnOnGrey) {
  const TempDir dir;
  const auto rig = writeRig(dir, [](YAML::Node& yaml) {
    for (YAML::Node camera : yaml["cameras"]) {
      camera["source"] = YAML::Load("{device: /dev/video-not-opened}");
    }
  });
  const auto config = writeConfig(dir, rig, kVehicle);
  const CalibrateRun run = calibrate(dir, {"mask", "--config", config.string(), "--out",
                                           (dir / "masks").string(), "--camera", "front"});
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr("live camera"));
  const daemon::Config loaded = daemon::loadConfig(config);
  WorkPool pool(1);
  const cv::Mat expected = daemon::bodyMaskOf(loaded, 0, pool);
  expectSameMask(readMask(dir / "masks" / "front-body.png"), expected, "front");
  expectOverlay(cv::imread((dir / "masks" / "front-mask-overlay.png").string()),
                cv::Mat(expected.size(), CV_8UC3, cv::Scalar::all(64)), expected, "front");
}

TEST(MaskCli, BadInputExitsTwoNamingIt) {
  const TempDir dir;
  const auto config = writeConfig(dir, kRecording / "rig.yaml", kVehicle);
  CalibrateRun run = calibrate(dir, {"mask", "--config", config.string(), "--out",
                                     (dir / "masks").string(), "--camera", "roof"});
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_THAT(run.output, HasSubstr("surround-calibrate mask: --camera:"));
  EXPECT_THAT(run.output, HasSubstr("no camera 'roof' (its cameras: front, right, back, left)"));
  EXPECT_FALSE(std::filesystem::exists(dir / "masks"));

  run = calibrate(dir, {"mask", "--config", (dir / "missing.yaml").string(), "--out",
                        (dir / "masks").string()});
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_THAT(run.output, HasSubstr("missing.yaml"));

  run = calibrate(dir, {"mask", "--config", config.string()});
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_THAT(run.output, HasSubstr("--out: missing"));

  run = calibrate(dir, {"mask", "--help"});
  EXPECT_EQ(run.status, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr("usage: surround-calibrate mask --config FILE --out DIR"));
  run = calibrate(dir, {"--help"});
  EXPECT_THAT(run.output, HasSubstr("usage: surround-calibrate mask --config FILE --out DIR"));
}

// mask --from a drive: the polygons it prints, pasted into the rig as each camera's body_mask:,
// mask what the generator's true body masks say is body (the paper rig's roofs: IoU >= 0.95), and
// so does each -found-body.png.
TEST(MaskFromDrive, ThePolygonsPastedIntoTheRigMaskTheBody) {
  const TempDir dir;
  const auto drive = std::filesystem::path(SURROUNDD_FIXTURE_DIR) / "synth_drive_paper";
  const CalibrateRun run =
      calibrate(dir, {"mask", "--from", drive.string(), "--out", (dir / "masks").string()});
  ASSERT_EQ(run.status, 0) << run.output;
  const YAML::Node truth = YAML::LoadFile((drive / "ground_truth.yaml").string());
  daemon::RigFile rig = daemon::loadRig(drive / "rig.yaml");
  for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
    const std::string name = rig.cameras[c].calibration.name;
    SCOPED_TRACE(name);
    EXPECT_THAT(run.output,
                ::testing::ContainsRegex(name + ": [0-9.]+ % of the picture is body \\(20 "
                                                "pictures, [0-9]+ % of the ground moved\\)"));
    // The printed YAML: "  - name: NAME\n    body_mask: {mode: add, polygon: ...}".
    const std::string heading = "  - name: " + name + "\n    body_mask: ";
    const auto at = run.output.find(heading);
    ASSERT_NE(at, std::string::npos) << run.output;
    const auto start = at + heading.size();
    YAML::Node mask = YAML::Load(run.output.substr(start, run.output.find('\n', start) - start));
    EXPECT_EQ(mask["mode"].as<std::string>(), "add");
    mask["mode"] = "replace";  // the polygons alone, for the comparison
    daemon::Diagnostics diagnostics;
    daemon::YamlObject object(mask, "body_mask", dir / "pasted.yaml", diagnostics);
    rig.cameras[c].bodyMask =
        daemon::readBodyMask(object, rig.cameras[c].calibration.intrinsics.imageSize);
    ASSERT_TRUE(diagnostics.empty()) << diagnostics.messages().front();

    const cv::Mat trueBody =
        cv::imread((drive / truth["cameras"][c]["body_mask"].as<std::string>()).string(),
                   cv::IMREAD_GRAYSCALE) > 0;
    const auto iou = [&](const cv::Mat& found) {
      return cv::countNonZero(found & trueBody) /
             static_cast<double>(cv::countNonZero(found | trueBody));
    };
    EXPECT_GE(iou(readMask(dir / "masks" / (name + "-found-body.png")) > 0), 0.95);
    daemon::Config config;
    config.cameras = rig.cameras;
    WorkPool pool(1);
    EXPECT_GE(iou(daemon::bodyMaskOf(config, c, pool) > 0), 0.95);
    EXPECT_TRUE(std::filesystem::exists(dir / "masks" / (name + "-found-overlay.png")));
  }
}

TEST(MaskFromDrive, TooShortALiveOrAStillDriveExitsTwoNamingIt) {
  const TempDir dir;
  const auto fixtures = std::filesystem::path(SURROUNDD_FIXTURE_DIR);
  // 0.2 s of the paper rig: six pictures.
  CalibrateRun run = calibrate(dir, {"mask", "--from", (fixtures / "synth_body_paper").string(),
                                     "--out", (dir / "masks").string(), "--every", "0.1"});
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_THAT(run.output, HasSubstr("camera 'front': "));
  EXPECT_THAT(run.output,
              HasSubstr("gives 2 pictures 0.1 s apart; at least 16 are needed (a drive of 1.6 s"));

  // Ten seconds of one picture: the car stood still.
  const cv::Mat still = firstFrame(daemon::loadRig(kRecording / "rig.yaml").cameras.front());
  for (int i = 0; i < 20; ++i) {
    cv::imwrite((dir / fmt::format("still_{:04d}.png", i)).string(), still);
  }
  const auto rig = writeRig(dir, [&](YAML::Node& yaml) {
    for (YAML::Node camera : yaml["cameras"]) {
      camera["source"] =
          YAML::Load("{file: " + (dir / "still_%04d.png").string() + ", sequence_fps: 2}");
    }
  });
  run = calibrate(dir, {"mask", "--from", rig.string(), "--out", (dir / "masks").string(),
                        "--camera", "front"});
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_THAT(run.output, HasSubstr("the car must drive while it records"));

  const auto live = writeRig(dir, [](YAML::Node& yaml) {
    for (YAML::Node camera : yaml["cameras"]) {
      camera["source"] = YAML::Load("{device: /dev/video-not-opened}");
    }
  });
  run = calibrate(dir, {"mask", "--from", live.string(), "--out", (dir / "masks").string()});
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_THAT(run.output, HasSubstr("camera 'front' is live, not recorded"));

  run = calibrate(dir, {"mask", "--from", live.string(), "--config", live.string(), "--out",
                        (dir / "masks").string()});
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_THAT(run.output, HasSubstr("expected either --config"));
  EXPECT_FALSE(std::filesystem::exists(dir / "masks"));
}

}  // namespace
}  // namespace surroundd::calibration::testing
