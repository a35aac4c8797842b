// surround-calibrate refine on the shared real fisheye sample (../shared/data/pjlab-fisheye-real;
// skipped without it), perturbed as its own tool perturbs it (PJLab SensorsCalibration's
// auto_calib_fisheye): the ground -> camera matrices T of calibration.yaml become T * D, D = [R |
// t], R = Rz(c) Ry(b) Rx(a) about the ground frame's axes, for left, right and back; the front is
// left. Imported like the unperturbed file and refined from the sample's one set of pictures. The
// figures are printed for the record; what is asserted is that no camera ends further from its
// unperturbed mount than it began: one still set of pale asphalt gives 10-20 comparisons a
// seam, too few to correct 3-4 degrees conclusively (issue 48's target, 0.3 degrees, is not met
// on it), and an inconclusive correction is left out.

#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <yaml-cpp/yaml.h>

#include "daemon/config/rig_yaml.hpp"
#include "processing/calibration/seam_misalignment.hpp"
#include "tests/calibration/import_test_support.hpp"
#include "tests/support/temp_dir.hpp"
#include "tools/calibrate/refine/refine_command.hpp"

namespace surroundd::calibrate {
namespace {

using surroundd::testing::TempDir;

constexpr double kDegree = std::numbers::pi / 180;

std::filesystem::path sample() {
  return std::filesystem::path(SURROUNDD_SOURCE_DIR) / ".." / "shared" / "data" /
         "pjlab-fisheye-real";
}

struct Perturbation {
  cv::Vec3d anglesDeg;  // a, b, c
  cv::Vec3d translation;
};

// The tool's perturbations (its src/optimizer.cpp), in the file's own unit.
const std::map<std::string, Perturbation> kPerturbations{
    {"left", {{0.95, 1.25, -2.86}, {0.0095, 0.0025, -0.0086}}},
    {"right", {{-2.95, 1.25, -2.8}, {0.0065, -0.0075, 0.0095}}},
    {"back", {{-1.75, 2.95, -1.8}, {-0.002, -0.0076, 0.0096}}}};

cv::Matx44d perturbation(const Perturbation& p) {
  const auto about = [](int axis, double degrees) {
    cv::Vec3d v(0, 0, 0);
    v[axis] = degrees * kDegree;
    cv::Matx33d r;
    cv::Rodrigues(v, r);
    return r;
  };
  const cv::Matx33d r =
      about(2, p.anglesDeg[2]) * about(1, p.anglesDeg[1]) * about(0, p.anglesDeg[0]);
  cv::Matx44d d = cv::Matx44d::eye();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) d(i, j) = r(i, j);
    d(i, 3) = p.translation[i];
  }
  return d;
}

// calibration.yaml with T -> T * D for the perturbed cameras.
void writePerturbed(const std::filesystem::path& to) {
  YAML::Node file = YAML::LoadFile((sample() / "calibration.yaml").string());
  for (const auto& [name, p] : kPerturbations) {
    YAML::Node t = file["cameras"][name]["T_cam_from_G"];
    cv::Matx44d m;
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) m(i, j) = t[i][j].as<double>();
    }
    const cv::Matx44d perturbed = m * perturbation(p);
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) t[i][j] = perturbed(i, j);
    }
  }
  std::ofstream(to) << file;
}

// The import of config/rigs/imported/README.md, with the vehicle of config/real's config (its
// body masks) added to the rig file.
std::vector<daemon::RigCamera> importAs(const std::filesystem::path& calibration,
                                        const std::filesystem::path& rig) {
  const std::vector<std::string> arguments{"--pjlab-yaml",
                                           calibration.string(),
                                           "--lens",
                                           "fisheye",
                                           "--axes",
                                           "right,forward,up",
                                           "--unit-m",
                                           "0.1",
                                           "--ground-z",
                                           "1",
                                           "--origin-centre",
                                           "--images",
                                           (sample() / "imgs").string(),
                                           "--out",
                                           rig.string()};
  std::ostringstream log;
  runImport(parseImport(std::vector<std::string_view>(arguments.begin(), arguments.end())), log);
  const YAML::Node config =
      YAML::LoadFile(std::string(SURROUNDD_SOURCE_DIR) + "/config/real/pjlab-fisheye-real.yaml");
  YAML::Emitter vehicle;
  vehicle << YAML::Flow << config["vehicle"];
  std::ofstream(rig, std::ios::app) << "vehicle: " << vehicle.c_str() << "\n";
  return daemon::loadRigFile(rig);
}

double degreesBetween(const cv::Matx33d& a, const cv::Matx33d& b) {
  cv::Vec3d rotation;
  cv::Rodrigues(a.t() * b, rotation);
  return cv::norm(rotation) / kDegree;
}

double cpuSeconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

TEST(RefineSharedSample, NeverTakesThePerturbedRealFisheyeRigFurtherFromItsMounts) {
  if (!std::filesystem::is_directory(sample())) GTEST_SKIP() << "../shared/data is absent";
  const TempDir dir;
  const auto unperturbed = importAs(sample() / "calibration.yaml", dir / "unperturbed.yaml");
  writePerturbed(dir / "perturbed-calibration.yaml");
  importAs(dir / "perturbed-calibration.yaml", dir / "rig.yaml");
  const auto perturbed = daemon::loadRigFile(dir / "rig.yaml");

  std::ostringstream log;
  const auto wall = std::chrono::steady_clock::now();
  const double cpu = cpuSeconds();
  RefineOptions options;
  options.rig = dir / "rig.yaml";
  options.out = dir / "out";
  options.updateRig = true;
  runRefine(options, log);
  const double wallS =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall).count();
  const double cpuS = cpuSeconds() - cpu;
  std::cout << log.str();
  const auto refined = daemon::loadRigFile(dir / "rig.yaml");

  ASSERT_EQ(refined.size(), unperturbed.size());
  for (std::size_t c = 0; c < refined.size(); ++c) {
    const auto& name = refined[c].calibration.name;
    const double before = degreesBetween(perturbed[c].calibration.pose.rotation,
                                         unperturbed[c].calibration.pose.rotation);
    const double after = degreesBetween(refined[c].calibration.pose.rotation,
                                        unperturbed[c].calibration.pose.rotation);
    std::cout << fmt::format(
        "[ measured ] {}: {:.2f} deg from the unperturbed mount, {:.2f} after\n", name, before,
        after);
    EXPECT_LE(after, before + 1e-9) << name;
  }
  std::cout << fmt::format("[ measured ] refine took {:.1f} s ({:.1f} s of CPU)\n", wallS, cpuS);
}

// The CARLA sample's calibration is exact: refining it from its pictures leaves every camera
// within 0.05 degrees (what the fit finds, 0.1-0.2 degrees, is under what it acts on).
TEST(RefineSharedSample, LeavesTheExactSimulatorRigAsItIs) {
  const auto carla = sample().parent_path() / "pjlab-carla-pinhole";
  if (!std::filesystem::is_directory(carla)) GTEST_SKIP() << "../shared/data is absent";
  const TempDir dir;
  const std::vector<std::string> arguments{"--pjlab",    carla.string(),
                                           "--axes",     "right,back,down",
                                           "--ground-z", "5.1",
                                           "--images",   (carla / "imgs").string(),
                                           "--out",      (dir / "rig.yaml").string()};
  std::ostringstream log;
  runImport(parseImport(std::vector<std::string_view>(arguments.begin(), arguments.end())), log);
  const auto imported = daemon::loadRigFile(dir / "rig.yaml");
  RefineOptions options;
  options.rig = dir / "rig.yaml";
  options.images = carla / "imgs";
  options.out = dir / "out";
  options.updateRig = true;
  runRefine(options, log);
  std::cout << log.str();
  const auto refined = daemon::loadRigFile(dir / "rig.yaml");
  for (std::size_t c = 0; c < refined.size(); ++c) {
    const double moved =
        degreesBetween(refined[c].calibration.pose.rotation, imported[c].calibration.pose.rotation);
    std::cout << fmt::format("[ measured ] {}: moved {:.3f} deg\n", refined[c].calibration.name,
                             moved);
    EXPECT_LT(moved, 0.05) << refined[c].calibration.name;
  }
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "top-after.png"));
}

}  // namespace
}  // namespace surroundd::calibrate
