// surround-calibrate intrinsics on injected failures (a wrong board size, repeated pictures, a
// blurred picture, a solve outside its limits): each is refused with a message that names what
// was wrong, a non-zero exit, and nothing written. And on Debian's opencv-doc photographs (skipped
// without the package), against an independent cv::calibrateCamera solve.

#include <chrono>
#include <filesystem>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <yaml-cpp/yaml.h>

#include "tests/calibration/board_views_support.hpp"
#include "tests/calibration/calibrate_run.hpp"
#include "tests/support/temp_dir.hpp"

namespace surroundd::calibration::testing {
namespace {

using surroundd::testing::TempDir;
using ::testing::HasSubstr;

std::filesystem::path writeViews(const TempDir& dir, const std::vector<cv::Mat>& images) {
  const auto folder = dir / "views";
  std::filesystem::create_directories(folder);
  for (std::size_t i = 0; i < images.size(); ++i) {
    cv::imwrite((folder / fmt::format("view_{:02}.png", i)).string(), images[i]);
  }
  return folder;
}

std::vector<std::string> arguments(const TempDir& dir, const std::filesystem::path& images,
                                   const std::string& board) {
  return {"intrinsics",
          "--images",
          images.string(),
          "--board",
          board,
          "--model",
          "pinhole",
          "--out",
          (dir / "lens.yaml").string(),
          "--coverage",
          (dir / "coverage.png").string()};
}

void expectRefused(const CalibrateRun& run, int status, const std::string& message,
                   const TempDir& dir) {
  EXPECT_EQ(run.status, status) << run.output;
  EXPECT_THAT(run.output, HasSubstr(message));
  EXPECT_FALSE(std::filesystem::exists(dir / "lens.yaml"));
  EXPECT_FALSE(std::filesystem::exists(dir / "coverage.png"));
}

const processing::Intrinsics& pinhole() {
  static const auto lens = presetCameras("paper.yaml").front().intrinsics;
  return lens;
}

TEST(IntrinsicsCli, ASquareBoardPassesWithItsTable) {
  const TempDir dir;
  const auto images = writeViews(dir, anyBoardViews(pinhole(), chessboard(7, 7), 8, 21));
  auto args = arguments(dir, images, "7x7");
  args.insert(args.end(), {"--square", "25"});
  const auto run = calibrate(dir, args);
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr("distance m"));
  EXPECT_THAT(run.output, HasSubstr("fx "));
  EXPECT_THAT(run.output, HasSubstr(" +- "));
  EXPECT_THAT(run.output, HasSubstr("verdict: PASS"));
  EXPECT_TRUE(std::filesystem::exists(dir / "coverage.png"));
}

TEST(IntrinsicsCli, AWrongBoardSizeIsRefusedInSeconds) {
  const TempDir dir;
  const auto images = writeViews(dir, anyBoardViews(pinhole(), chessboard(7, 7), 6, 22));
  const auto start = std::chrono::steady_clock::now();
  const auto run = calibrate(dir, arguments(dir, images, "6x5"));
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  expectRefused(run, 2, "--board 6x5: the pictures show a larger chessboard grid (7x7 in view_",
                dir);
  RecordProperty("seconds", std::to_string(seconds));
  std::cout << "wrong board size refused in " << seconds << " s\n";
}

TEST(IntrinsicsCli, RepeatedPicturesAreSkippedAndLeaveTooFew) {
  const TempDir dir;
  auto views = anyBoardViews(pinhole(), chessboard(9, 6), 4, 23);
  views.push_back(views[0].clone());
  views.push_back(views[2].clone());
  const auto images = writeViews(dir, views);
  expectRefused(calibrate(dir, arguments(dir, images, "9x6")), 1,
                "too few views: 4 usable (found in view_00.png, view_01.png, view_02.png, "
                "view_03.png), at least 5 are needed (from different angles and field positions); "
                "skipped: view_04.png: repeats view_00.png (the board outlines overlap 100 %); "
                "view_05.png: repeats view_02.png",
                dir);
}

TEST(IntrinsicsCli, ABlurredPictureIsSkippedAndNamed) {
  const TempDir dir;
  auto views = anyBoardViews(pinhole(), chessboard(9, 6), 5, 24);
  cv::GaussianBlur(views[3], views[3], {0, 0}, 3.0);
  const auto images = writeViews(dir, views);
  expectRefused(calibrate(dir, arguments(dir, images, "9x6")), 1,
                "view_03.png: too blurred: its edges are", dir);
}

TEST(IntrinsicsCli, ASolveOutsideItsLimitsWritesNothingAndNamesViews) {
  const TempDir dir;
  const auto images = writeViews(dir, anyBoardViews(pinhole(), chessboard(9, 6), 6, 25));
  auto args = arguments(dir, images, "9x6");
  args.insert(args.end(), {"--max-rms-px", "0.01", "--max-view-rms-px", "0.01"});
  const auto run = calibrate(dir, args);
  expectRefused(run, 1, "the solve failed its limits (RMS 0.0", dir);
  EXPECT_THAT(run.output, HasSubstr("verdict: FAIL"));
  EXPECT_THAT(run.output, HasSubstr("views to drop first (--exclude view_"));
  EXPECT_THAT(run.output, HasSubstr("<- above the limit"));
}

// Debian's opencv-doc: 13 photographs of a 9x6 board from each camera of a stereo pair.
const std::filesystem::path kOpencvDocData = "/usr/share/doc/opencv-doc/examples/data";

cv::Matx33d independentSolve(const std::vector<std::filesystem::path>& files, double& rms) {
  std::vector<std::vector<cv::Point3f>> objects;
  std::vector<std::vector<cv::Point2f>> corners;
  cv::Size size;
  for (const auto& file : files) {
    const cv::Mat gray = cv::imread(file.string(), cv::IMREAD_GRAYSCALE);
    size = gray.size();
    std::vector<cv::Point2f> found;
    if (!cv::findChessboardCorners(gray, {9, 6}, found)) continue;
    cv::cornerSubPix(gray, found, {11, 11}, {-1, -1},
                     {cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 30, 0.01});
    corners.push_back(found);
    objects.emplace_back();
    for (int j = 0; j < 6; ++j) {
      for (int i = 0; i < 9; ++i) objects.back().emplace_back(i, j, 0);
    }
  }
  cv::Matx33d k;
  cv::Mat d;
  std::vector<cv::Mat> r, t;
  rms = cv::calibrateCamera(objects, corners, size, k, d, r, t);
  return k;
}

TEST(IntrinsicsCli, OpencvDocPhotographsAgreeWithAnIndependentSolve) {
  if (!std::filesystem::exists(kOpencvDocData / "left01.jpg")) {
    GTEST_SKIP() << "opencv-doc is not installed (" << kOpencvDocData << ")";
  }
  for (const std::string side : {"left", "right"}) {
    const TempDir dir;
    std::filesystem::create_directories(dir / "views");
    std::vector<std::filesystem::path> files;
    for (int i = 1; i <= 14; ++i) {
      const auto file = kOpencvDocData / fmt::format("{}{:02}.jpg", side, i);
      if (!std::filesystem::exists(file)) continue;
      files.push_back(file);
      std::filesystem::copy_file(file, dir / "views" / file.filename());
    }
    const auto run =
        calibrate(dir, {"intrinsics", "--images", (dir / "views").string(), "--board", "9x6",
                        "--model", "pinhole", "--out", (dir / "lens.yaml").string()});
    ASSERT_EQ(run.status, 0) << run.output;
    const YAML::Node lens = YAML::LoadFile((dir / "lens.yaml").string())["lens"];
    double rms = 0;
    const auto k = independentSolve(files, rms);
    const double fx = lens["fx_px"].as<double>(), fy = lens["fy_px"].as<double>();
    const double cx = lens["cx_px"].as<double>(), cy = lens["cy_px"].as<double>();
    const auto figures = fmt::format(
        "{}: fx {:.2f} ({:+.2f} %), fy {:.2f} ({:+.2f} %), cx {:.2f} ({:+.2f} px), cy {:.2f} "
        "({:+.2f} px); independent RMS {:.3f} px",
        side, fx, 100 * (fx / k(0, 0) - 1), fy, 100 * (fy / k(1, 1) - 1), cx, cx - k(0, 2), cy,
        cy - k(1, 2), rms);
    std::cout << figures << "\n" << run.output.substr(run.output.find("RMS ")) << "\n";
    RecordProperty(side, figures);
    EXPECT_NEAR(fx / k(0, 0), 1, 0.01);
    EXPECT_NEAR(fy / k(1, 1), 1, 0.01);
    EXPECT_NEAR(cx, k(0, 2), 3);
    EXPECT_NEAR(cy, k(1, 2), 3);
  }
}

}  // namespace
}  // namespace surroundd::calibration::testing
