// Debian's opencv-doc photographs (13 of a 9x6 board from each camera of a stereo pair; skipped
// without the package): every picture's corners found and labelled as the classic detector
// labels them, and surround-calibrate intrinsics, run as documented, using every picture and
// agreeing with an independent cv::calibrateCamera solve on the classic detector's corners.

#include <filesystem>
#include <string_view>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <yaml-cpp/yaml.h>

#include "processing/calibration/calibration_board.hpp"
#include "tests/calibration/calibrate_run.hpp"
#include "tests/support/temp_dir.hpp"

namespace surroundd::calibration::testing {
namespace {

using surroundd::testing::TempDir;
using ::testing::HasSubstr;
using ::testing::Not;

constexpr std::string_view kData = "/usr/share/doc/opencv-doc/examples/data";
constexpr int kColumns = 9, kRows = 6;  // inner corners

std::vector<std::filesystem::path> pictures(const std::string& side) {
  std::vector<std::filesystem::path> files;
  for (int i = 1; i <= 14; ++i) {  // there is no number 10
    const auto file = std::filesystem::path(kData) / fmt::format("{}{:02}.jpg", side, i);
    if (std::filesystem::exists(file)) files.push_back(file);
  }
  return files;
}

// OpenCV's classic detector and refinement, with an 11x11 window: the smallest squares in these
// pictures are 21 px, and the 23x23 window of OpenCV's calibration sample reaches the next
// corners, which moves its corners by up to 6 px (its solve: RMS 0.46 px against 0.21, fx 542
// against 537 on the right camera).
std::optional<std::vector<cv::Point2f>> classicCorners(const cv::Mat& gray) {
  std::vector<cv::Point2f> found;
  if (!cv::findChessboardCorners(gray, {kColumns, kRows}, found)) return std::nullopt;
  cv::cornerSubPix(gray, found, {5, 5}, {-1, -1},
                   {cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 30, 0.01});
  return found;
}

class OpencvDoc : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    if (!std::filesystem::exists(std::filesystem::path(kData) / "left01.jpg")) {
      GTEST_SKIP() << "opencv-doc is not installed (" << kData << ")";
    }
  }
};

// The labels may differ from the classic detector's by the board's symmetries (which end is
// first, rows for columns) but must map onto them by one of those for every corner: a grid grown
// in strides that skip corners, or onto the board's outline, does not.
TEST_P(OpencvDoc, EveryPictureIsFoundWholeAndLabelledAsTheClassicDetectorLabelsIt) {
  for (const auto& file : pictures(GetParam())) {
    SCOPED_TRACE(file.filename().string());
    const cv::Mat gray = cv::imread(file.string(), cv::IMREAD_GRAYSCALE);
    const auto classic = classicCorners(gray);
    ASSERT_TRUE(classic);
    const auto found =
        processing::findBoard(gray, {processing::BoardKind::kChessboard, {kColumns, kRows}});
    ASSERT_EQ(found.outcome, processing::BoardSearch::Outcome::kFound);
    ASSERT_EQ(found.corners.size(), classic->size());
    // Each corner's classic label: the classic corner it sits on.
    std::vector<cv::Point> labels;
    for (const auto& corner : found.corners) {
      std::size_t nearest = 0;
      for (std::size_t k = 1; k < classic->size(); ++k) {
        if (cv::norm((*classic)[k] - corner) < cv::norm((*classic)[nearest] - corner)) nearest = k;
      }
      // On the same corner: within a quarter of the smallest square (21 px). Where the two
      // refinements differ by more than a pixel or two, the solves judge which is better.
      EXPECT_LT(cv::norm((*classic)[nearest] - corner), 5.0);
      labels.emplace_back(static_cast<int>(nearest) % kColumns,
                          static_cast<int>(nearest) / kColumns);
    }
    // The map from our (column, row) to the classic one, from grid (0, 0) and its neighbours.
    const auto labelAt = [&](cv::Point g) {
      for (std::size_t k = 0; k < found.grid.size(); ++k) {
        if (found.grid[k] == g) return labels[k];
      }
      ADD_FAILURE() << "no corner at " << g;
      return cv::Point();
    };
    const cv::Point origin = labelAt({0, 0});
    const cv::Point alongColumns = labelAt({1, 0}) - origin, alongRows = labelAt({0, 1}) - origin;
    EXPECT_EQ(std::abs(alongColumns.x) + std::abs(alongColumns.y), 1);
    EXPECT_EQ(std::abs(alongRows.x) + std::abs(alongRows.y), 1);
    for (std::size_t k = 0; k < found.grid.size(); ++k) {
      EXPECT_EQ(labels[k], origin + found.grid[k].x * alongColumns + found.grid[k].y * alongRows)
          << "corner at " << found.grid[k];
    }
  }
}

cv::Matx33d independentSolve(const std::vector<std::filesystem::path>& files, double& rms) {
  std::vector<std::vector<cv::Point3f>> objects;
  std::vector<std::vector<cv::Point2f>> corners;
  cv::Size size;
  for (const auto& file : files) {
    const cv::Mat gray = cv::imread(file.string(), cv::IMREAD_GRAYSCALE);
    size = gray.size();
    const auto found = classicCorners(gray);
    if (!found) continue;
    corners.push_back(*found);
    objects.emplace_back();
    for (int j = 0; j < kRows; ++j) {
      for (int i = 0; i < kColumns; ++i) objects.back().emplace_back(i, j, 0);
    }
  }
  cv::Matx33d k;
  cv::Mat d;
  std::vector<cv::Mat> r, t;
  rms = cv::calibrateCamera(objects, corners, size, k, d, r, t);
  return k;
}

TEST_P(OpencvDoc, TheDocumentedCommandUsesEveryPictureAndAgreesWithAnIndependentSolve) {
  const std::string side = GetParam();
  const TempDir dir;
  std::filesystem::create_directories(dir / "views");
  const auto files = pictures(side);
  for (const auto& file : files) std::filesystem::copy_file(file, dir / "views" / file.filename());
  const auto run =
      calibrate(dir, {"intrinsics", "--images", (dir / "views").string(), "--board", "9x6",
                      "--model", "pinhole", "--out", (dir / "lens.yaml").string()});
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_THAT(run.output, Not(HasSubstr("skipped")));
  EXPECT_THAT(run.output, Not(HasSubstr("left out")));
  EXPECT_THAT(run.output, HasSubstr(fmt::format("in {} views", files.size())));
  EXPECT_THAT(run.output, Not(HasSubstr("field of view 0.0 deg")));
  const YAML::Node lens = YAML::LoadFile((dir / "lens.yaml").string())["lens"];
  double rms = 0;
  const auto k = independentSolve(files, rms);
  const double fx = lens["fx_px"].as<double>(), fy = lens["fy_px"].as<double>();
  const double cx = lens["cx_px"].as<double>(), cy = lens["cy_px"].as<double>();
  const auto figures = fmt::format(
      "{}: fx {:.2f} ({:+.2f} %), fy {:.2f} ({:+.2f} %), cx {:.2f} ({:+.2f} px), cy {:.2f} "
      "({:+.2f} px); independent: fx {:.2f} fy {:.2f} cx {:.2f} cy {:.2f}, RMS {:.3f} px",
      side, fx, 100 * (fx / k(0, 0) - 1), fy, 100 * (fy / k(1, 1) - 1), cx, cx - k(0, 2), cy,
      cy - k(1, 2), k(0, 0), k(1, 1), k(0, 2), k(1, 2), rms);
  std::cout << figures << "\n" << run.output.substr(run.output.find("RMS ")) << "\n";
  RecordProperty("figures", figures);
  EXPECT_NEAR(fx / k(0, 0), 1, 0.005);
  EXPECT_NEAR(fy / k(1, 1), 1, 0.005);
  EXPECT_NEAR(cx, k(0, 2), 2);
  EXPECT_NEAR(cy, k(1, 2), 2);
}

INSTANTIATE_TEST_SUITE_P(Cameras, OpencvDoc, ::testing::Values("left", "right"));

}  // namespace
}  // namespace surroundd::calibration::testing
