// surround-calibrate refine on the generated fisheye drive (synth_drive_fisheye_hd), its rig
// written with the back camera turned by two degrees and the body masked as rendered: the back
// camera's mount comes back to the true one in the rig file (the file before kept beside it),
// the others stay, and the pictures from above are written; bad arguments are named.

#include <filesystem>
#include <numbers>
#include <sstream>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <yaml-cpp/yaml.h>

#include "daemon/config/rig_yaml.hpp"
#include "tests/support/temp_dir.hpp"
#include "tools/calibrate/calibrate_options.hpp"
#include "tools/calibrate/refine/refine_command.hpp"

namespace surroundd::calibrate {
namespace {

using surroundd::testing::TempDir;

constexpr double kDegree = std::numbers::pi / 180;

double degreesBetween(const cv::Matx33d& a, const cv::Matx33d& b) {
  cv::Vec3d rotation;
  cv::Rodrigues(a.t() * b, rotation);
  return cv::norm(rotation) / kDegree;
}

Command parse(std::vector<std::string_view> arguments) { return parseArguments(arguments); }

TEST(RefineCli, BringsTheTurnedCameraBackInTheRigFile) {
  const auto drive = std::filesystem::path(SURROUNDD_FIXTURE_DIR) / "synth_drive_fisheye_hd";
  const TempDir dir;
  const daemon::RigFile generated = daemon::loadRig(drive / "rig.yaml");
  auto cameras = generated.cameras;
  const auto truth = cameras;
  const YAML::Node written = YAML::LoadFile((drive / "ground_truth.yaml").string());
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    cameras[c].bodyMask =
        daemon::BodyMaskConfig{daemon::BodyMaskConfig::Mode::kReplace,
                               drive / written["cameras"][c]["body_mask"].as<std::string>(),
                               {}};
  }
  cv::Matx33d turn;
  cv::Rodrigues(cv::Vec3d(0, 2, 1) * kDegree, turn);
  cameras[2].calibration.pose.rotation = turn * cameras[2].calibration.pose.rotation;
  const auto rig = dir / "rig.yaml";
  daemon::writeRigFile(rig, cameras, "the generated drive, its back camera turned",
                       generated.vehicle ? &*generated.vehicle : nullptr);

  const std::string rigText = rig.string();
  const std::string outText = (dir / "out").string();
  const Command command = parse({"refine", "--rig", rigText, "--out", outText, "--update-rig"});
  std::ostringstream log;
  runRefine(std::get<RefineOptions>(command), log);
  std::cout << log.str();

  const auto refined = daemon::loadRigFile(rig);
  for (std::size_t c = 0; c < refined.size(); ++c) {
    EXPECT_LT(
        degreesBetween(refined[c].calibration.pose.rotation, truth[c].calibration.pose.rotation),
        0.12)
        << refined[c].calibration.name;
  }
  EXPECT_GT(degreesBetween(
                daemon::loadRigFile(rig.string() + ".before-refine")[2].calibration.pose.rotation,
                truth[2].calibration.pose.rotation),
            2.0);
  for (const char* file : {"mounts.yaml", "top-before.png", "top-after.png"}) {
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / file)) << file;
  }
}

TEST(RefineCli, NamesWhatIsWrongWithItsArguments) {
  const auto message = [](std::vector<std::string_view> arguments) {
    try {
      parse(std::move(arguments));
    } catch (const UsageError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message({"refine", "--out", "x"}).find("either --config"), std::string::npos);
  EXPECT_NE(message({"refine", "--rig", "r", "--config", "c", "--out", "x"}).find("either"),
            std::string::npos);
  EXPECT_NE(message({"refine", "--rig", "r"}).find("--out"), std::string::npos);
  EXPECT_NE(message({"refine", "--rig", "r", "--out", "x", "--every", "0"}).find("--every"),
            std::string::npos);

  const TempDir dir;
  RefineOptions options;
  options.rig = std::filesystem::path(SURROUNDD_FIXTURE_DIR) / "synth_drive_fisheye_hd";
  options.images = dir.path();  // no picture in it
  options.out = dir / "out";
  std::ostringstream log;
  try {
    runRefine(options, log);
    ADD_FAILURE() << "an empty --images folder was taken";
  } catch (const UsageError& error) {
    EXPECT_NE(std::string(error.what()).find("front"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace surroundd::calibrate
