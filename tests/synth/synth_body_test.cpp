// The ego vehicle's body in synthetic recordings: a preset with a `vehicle:` block gets the body
// rendered into the cameras that see it and true body masks in its ground truth; the masks are
// exactly the pixels the body changes; the stitcher's masks, computed from the coarser prism of
// processing::VehicleBody, agree with them; and a rig without `vehicle:` has no body at all.

#include <gtest/gtest.h>

#include "common/work_pool.hpp"
#include "daemon/config/rig_yaml.hpp"
#include "processing/lens/camera_model.hpp"
#include "processing/vehicle_body.hpp"
#include "tests/synth/synth_test_support.hpp"

namespace surroundd::synth {
namespace {

struct Recording {
  std::filesystem::path folder;
  YAML::Node truth;
  daemon::RigFile rig;
};

Recording load(const std::string& fixture) {
  Recording r;
  r.folder = testing::fixture(fixture);
  r.truth = YAML::LoadFile((r.folder / "ground_truth.yaml").string());
  r.rig = daemon::loadRig(r.folder / "rig.yaml");
  return r;
}

cv::Mat trueMask(const Recording& recording, const std::string& camera) {
  for (const auto& entry : recording.truth["cameras"]) {
    if (entry["name"].as<std::string>() != camera) continue;
    return cv::imread((recording.folder / entry["body_mask"].as<std::string>()).string(),
                      cv::IMREAD_UNCHANGED);
  }
  return {};
}

TEST(SynthBody, RoofCamerasSeeTheRoofAtTheBottomAndNoBodyAboveIt) {
  const Recording recording = load("synth_body_paper");
  ASSERT_TRUE(recording.rig.vehicle.has_value()) << "rig.yaml must carry the vehicle";
  const double roof = recording.rig.vehicle->heightM;
  for (const auto& camera : recording.rig.cameras) {
    const auto& cal = camera.calibration;
    const cv::Mat mask = trueMask(recording, cal.name);
    ASSERT_EQ(mask.type(), CV_8U) << cal.name;
    ASSERT_EQ(mask.size(), cal.intrinsics.imageSize) << cal.name;
    // The middle of the bottom row looks down onto the roof (the cameras stand above it).
    const int bottom = mask.rows - 1;
    EXPECT_EQ(mask.at<std::uint8_t>(bottom, mask.cols / 2), 255) << cal.name;
    EXPECT_GT(cv::countNonZero(mask.row(bottom)), mask.cols / 2) << cal.name;
    // A ray that does not go down from a camera above the roof cannot meet the body.
    ASSERT_GT(cal.pose.position[2], roof + 0.1) << cal.name;
    const processing::CameraModel model(cal.intrinsics);
    int rising = 0;
    for (int v = 0; v < mask.rows; ++v) {
      for (int u = 0; u < mask.cols; ++u) {
        const auto ray = model.unproject(cv::Point2d(u, v));
        if (!ray || (cal.pose.rotation * *ray)[2] < 0) continue;
        ++rising;
        EXPECT_EQ(mask.at<std::uint8_t>(v, u), 0) << cal.name << " pixel " << u << "," << v;
        if (mask.at<std::uint8_t>(v, u) != 0) return;  // one failure says it
      }
    }
    EXPECT_GT(rising, mask.total() / 10) << cal.name;
  }
}

// The same rig rendered without the body (--no-body): unmasked pixels are the same bytes, masked
// ones are the body's.
TEST(SynthBody, MaskIsExactlyWhereTheBodyChangesThePicture) {
  const Recording body = load("synth_body_paper");
  const Recording plain = load("synth_body_paper_plain");
  ASSERT_FALSE(plain.rig.vehicle.has_value());
  ASSERT_FALSE(plain.truth["cameras"][0]["body_mask"]);
  for (const auto& camera : body.rig.cameras) {
    const std::string& name = camera.calibration.name;
    const cv::Mat mask = trueMask(body, name);
    ASSERT_FALSE(mask.empty());
    for (const auto& frame : body.truth["ground_truth_frames"]) {
      const auto image = frame["cameras"][name]["image"].as<std::string>();
      const cv::Mat withBody = cv::imread((body.folder / image).string());
      const cv::Mat without = cv::imread((plain.folder / image).string());
      ASSERT_EQ(withBody.size(), without.size());
      cv::Mat channels[3];
      cv::split(withBody != without, channels);
      const cv::Mat differs = channels[0] | channels[1] | channels[2];
      EXPECT_EQ(cv::countNonZero(differs & ~mask), 0) << name << ": outside the mask";
      const int masked = cv::countNonZero(mask);
      ASSERT_GT(masked, 0) << name;
      // A reflection may by chance round to the very colour the ground had there.
      EXPECT_GE(cv::countNonZero(differs & mask), 0.98 * masked) << name << ": inside the mask";
    }
  }
}

// The stitcher's prism against the rendered body with its rounded corners and edges.
void expectComputedMasksMatch(const std::string& fixture) {
  const Recording recording = load(fixture);
  ASSERT_TRUE(recording.rig.vehicle.has_value());
  const auto body = recording.rig.vehicle->body();
  WorkPool pool(2);
  for (const auto& camera : recording.rig.cameras) {
    const auto& cal = camera.calibration;
    const cv::Mat truth = trueMask(recording, cal.name);
    ASSERT_FALSE(truth.empty()) << cal.name;
    const cv::Mat computed = processing::computeBodyMask(body, cal, pool);
    const double iou = processing::maskIoU(computed, truth);
    ::testing::Test::RecordProperty(fixture + "_" + cal.name + "_iou", std::to_string(iou));
    std::cout << fixture << " " << cal.name << ": IoU " << iou << " (" << cv::countNonZero(truth)
              << " true, " << cv::countNonZero(computed) << " computed pixels)\n";
    EXPECT_GT(cv::countNonZero(truth), 0) << cal.name;
    EXPECT_GE(iou, 0.95) << cal.name;
  }
}

TEST(SynthBody, ComputedMasksMatchTheTrueOnesOnTheRoofRig) {
  expectComputedMasksMatch("synth_body_paper");
}

TEST(SynthBody, ComputedMasksMatchTheTrueOnesOnTheFisheyeRig) {
  expectComputedMasksMatch("synth_body_fisheye");
}

TEST(SynthBody, RigWithoutVehicleHasNoBody) {
  const Recording recording = load("synth_small");
  EXPECT_FALSE(recording.rig.vehicle.has_value());
  EXPECT_FALSE(recording.truth["ego_body"]);
  for (const auto& camera : recording.truth["cameras"]) EXPECT_FALSE(camera["body_mask"]);
  EXPECT_FALSE(std::filesystem::exists(recording.folder / "ground_truth/body_mask_front.png"));
}

}  // namespace
}  // namespace surroundd::synth
