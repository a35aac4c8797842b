// surround-calibrate import of the files surround-view-system-introduction's bird's-eye tool
// writes (issue 47): per camera an OpenCV FileStorage file with camera_matrix, dist_coeffs
// (fisheye), resolution, project_matrix (the undistorted picture to the camera's strip of the
// canvas), scale_xy and shift_xy (the undistorted picture's K' = K with fx, fy scaled and cx, cy
// shifted). Generated here from the fisheye rig preset the way that tool lays its canvas out, the
// layout checked with the picture operations that tool does, and imported back to the preset.

#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "tests/calibration/import_test_support.hpp"
#include "tests/support/temp_dir.hpp"
#include "tools/calibrate/calibrate_options.hpp"
#include "tools/calibrate/import/import_command.hpp"

namespace surroundd::calibrate {
namespace {

using surroundd::testing::TempDir;
using ::testing::AllOf;
using ::testing::HasSubstr;

// That tool's canvas (param_settings.py): 1 cm per pixel, x right, y towards the rear, the
// vehicle's centre at the middle; the front and back strips 550 rows deep, the sides 500 columns.
const cv::Size kCanvas(1200, 1600);
constexpr int kFrontRows = 550;
constexpr int kSideColumns = 500;
const ForeignFrame kBirdView{"right,back,down", {0, -1, 0, -1, 0, 0, 0, 0, -1}, 0.01, 0, {0, 0, 0}};
const cv::Vec2d kScale(0.7, 0.8);
const cv::Vec2d kShift(-120, -90);

// Canvas pixel -> the camera's strip pixel, written out for each side (the importer's own table
// is what is under test; this one is checked against that tool's picture operations below).
cv::Matx33d stripFromCanvasOf(const std::string& side) {
  const double w = kCanvas.width - 1.0, h = kCanvas.height - 1.0;
  if (side == "back") return {-1, 0, w, 0, -1, h, 0, 0, 1};
  if (side == "left") return {0, -1, h, 1, 0, 0, 0, 0, 1};
  if (side == "right") return {0, 1, 0, -1, 0, w, 0, 0, 1};
  return cv::Matx33d::eye();
}

cv::Matx33d undistortedCamera(const processing::Intrinsics& lens) {
  return {lens.fx * kScale[0],
          0,
          lens.cx + kShift[0],
          0,
          lens.fy * kScale[1],
          lens.cy + kShift[1],
          0,
          0,
          1};
}

// Canvas pixel -> the undistorted picture: K' [r1 r2 t] S^-1, S the ground (cm) to canvas pixels.
cv::Matx33d canvasToPicture(const CameraCalibration& camera) {
  const auto [r, t] = kBirdView.cameraFromSource(camera.pose);
  const cv::Matx33d plane(r(0, 0), r(0, 1), t[0], r(1, 0), r(1, 1), t[1], r(2, 0), r(2, 1), t[2]);
  const cv::Matx33d groundToCanvas(1, 0, kCanvas.width / 2.0, 0, 1, kCanvas.height / 2.0, 0, 0, 1);
  return undistortedCamera(camera.intrinsics) * plane * groundToCanvas.inv();
}

cv::Matx33d projectMatrix(const CameraCalibration& camera) {
  return stripFromCanvasOf(camera.name) * canvasToPicture(camera).inv();
}

// The camera's strip as that tool makes it (birdview.py: warpPerspective to the project shape,
// then flip), and where it lands on the canvas.
std::pair<cv::Mat, cv::Rect> stripOnCanvas(const cv::Mat& picture,
                                           const CameraCalibration& camera) {
  const bool sideways = camera.name == "left" || camera.name == "right";
  const cv::Size shape =
      sideways ? cv::Size(kCanvas.height, kSideColumns) : cv::Size(kCanvas.width, kFrontRows);
  cv::Mat strip, turned;
  cv::warpPerspective(picture, strip, cv::Mat(projectMatrix(camera)), shape);
  if (camera.name == "front") return {strip, {0, 0, kCanvas.width, kFrontRows}};
  if (camera.name == "back") {
    cv::flip(strip, turned, -1);  // image[::-1, ::-1]
    return {turned, {0, kCanvas.height - kFrontRows, kCanvas.width, kFrontRows}};
  }
  cv::transpose(strip, strip);
  if (camera.name == "left") {
    cv::flip(strip, turned, 0);  // cv2.transpose(image)[::-1]
    return {turned, {0, 0, kSideColumns, kCanvas.height}};
  }
  cv::flip(strip, turned, 1);  // np.flip(cv2.transpose(image), 1)
  return {turned, {kCanvas.width - kSideColumns, 0, kSideColumns, kCanvas.height}};
}

std::vector<std::string> birdViewFiles(const TempDir& dir,
                                       const std::vector<CameraCalibration>& truth) {
  std::vector<std::string> arguments{"--out",           (dir / "rig.yaml").string(),
                                     "--lens",          "fisheye",
                                     "--canvas-strips", "1200x1600",
                                     "--canvas-scale",  "1",
                                     "--canvas-origin", "600,800"};
  for (const auto& camera : truth) {
    const auto file = dir / (camera.name + ".yaml");
    cv::FileStorage storage(file.string(), cv::FileStorage::WRITE);
    const auto& lens = camera.intrinsics;
    storage << "camera_matrix" << cameraMatrix(lens);
    storage << "dist_coeffs"
            << cv::Mat(std::vector<double>(lens.distortion.begin(), lens.distortion.begin() + 4));
    storage << "resolution" << cv::Mat(cv::Vec2i(lens.imageSize.width, lens.imageSize.height));
    storage << "project_matrix" << cv::Mat(projectMatrix(camera));
    cv::Mat scale, shift;
    cv::Mat(kScale).convertTo(scale, CV_32F);  // the tool writes float32
    cv::Mat(kShift).convertTo(shift, CV_32F);
    storage << "scale_xy" << scale << "shift_xy" << shift;
    storage.release();
    arguments.push_back("--camera");
    arguments.push_back(camera.name + "=" + file.string());
  }
  for (const auto& option : kBirdView.options()) arguments.push_back(option);
  return arguments;
}

TEST(ImportBirdView, TheGeneratedFilesLayTheCanvasOutAsThatToolDoes) {
  // A smooth texture, so that warping in one step or two differs only by rounding.
  cv::Mat noise(720, 1280, CV_32FC1), picture;
  cv::randu(noise, 0, 255);
  cv::GaussianBlur(noise, picture, {0, 0}, 6);
  for (const auto& camera : preset("fisheye.yaml")) {
    cv::Mat whole;
    cv::warpPerspective(picture, whole, cv::Mat(canvasToPicture(camera).inv()), kCanvas);
    const auto [strip, at] = stripOnCanvas(picture, camera);
    ASSERT_EQ(strip.size(), at.size()) << camera.name;
    cv::Mat difference;
    cv::absdiff(strip, whole(at), difference);
    const cv::Mat seen = (strip > 0) & (whole(at) > 0);
    EXPECT_GT(cv::countNonZero(seen), at.area() / 10) << camera.name << " sees its strip";
    EXPECT_LT(cv::mean(difference, seen)[0], 0.5) << camera.name;
  }
}

TEST(ImportBirdView, ProjectMatricesWithStripsAndScaledUndistortionImportToTheRig) {
  const TempDir dir;
  const auto truth = preset("fisheye.yaml");
  const auto imported = importWith(birdViewFiles(dir, truth));
  expectPoses(imported.cameras, truth, "bird's-eye project_matrix, strips, scale_xy/shift_xy");
  // Issue 47: within 1 mm and 0.01 degrees of the truth.
  for (std::size_t i = 0; i < truth.size(); ++i) {
    cv::Vec3d turn;
    cv::Rodrigues(imported.cameras[i].calibration.pose.rotation * truth[i].pose.rotation.t(), turn);
    EXPECT_LT(cv::norm(imported.cameras[i].calibration.pose.position - truth[i].pose.position),
              1e-3);
    EXPECT_LT(cv::norm(turn) * kRadToDeg, 0.01);
    expectSameLens(imported.cameras[i].calibration.intrinsics, truth[i].intrinsics, truth[i].name);
  }
  for (const auto& note : imported.notes) {
    EXPECT_THAT(note, AllOf(HasSubstr("pose fitted to the homography"), HasSubstr("0.00 px"),
                            ::testing::Not(HasSubstr("warning"))));
  }
  // Each camera says what it took from where.
  ASSERT_EQ(imported.sources.size(), truth.size());
  for (const auto& source : imported.sources) {
    EXPECT_THAT(source,
                AllOf(HasSubstr(".yaml: project_matrix (inverted"), HasSubstr(".yaml: scale_xy"),
                      HasSubstr(".yaml: shift_xy"), HasSubstr(".yaml: resolution"),
                      HasSubstr("lens model fisheye from --lens"), HasSubstr("(--canvas-strips)")));
  }
  const auto back = std::ranges::find_if(
      imported.sources, [](const std::string& s) { return s.starts_with("camera 'back'"); });
  ASSERT_NE(back, imported.sources.end());
  EXPECT_THAT(*back, AllOf(HasSubstr("back.yaml: camera_matrix"), HasSubstr("the back one")));
}

TEST(ImportBirdView, WithoutItsStripsOrItsScaleTheRigIsWarnedOfOrRefused) {
  const TempDir dir;
  const auto truth = preset("fisheye.yaml");
  auto arguments = birdViewFiles(dir, truth);
  // Without --canvas-strips each homography is taken to target the whole canvas: the back
  // camera, for one, then looks the wrong way, and the import says so (or finds no camera).
  auto whole = arguments;
  const auto strips = std::ranges::find(whole, "--canvas-strips");
  whole.erase(strips, strips + 2);
  try {
    const auto imported = importWith(whole);
    EXPECT_THAT(fmt::format("{}", fmt::join(imported.notes, "\n")),
                HasSubstr("warning: camera 'back'"));
  } catch (const UsageError& error) {
    EXPECT_THAT(error.what(), HasSubstr("back.yaml: project_matrix"));
  }
  // A camera with no side in its name has no strip.
  auto unnamed = arguments;
  const auto front = std::ranges::find(unnamed, "front=" + (dir / "front.yaml").string());
  ASSERT_NE(front, unnamed.end());
  *front = "nose=" + (dir / "front.yaml").string();
  EXPECT_THROW(
      {
        try {
          importWith(unnamed);
        } catch (const UsageError& error) {
          EXPECT_THAT(error.what(), AllOf(HasSubstr("--canvas-strips"), HasSubstr("'nose'")));
          throw;
        }
      },
      UsageError);
}

TEST(ImportBirdView, ASingularProjectMatrixOrANegativeScaleIsRefusedNamingTheFile) {
  const TempDir dir;
  const auto file = dir / "front.yaml";
  const auto write = [&](const cv::Matx33d& projection, const cv::Vec2d& scale) {
    cv::FileStorage storage(file.string(), cv::FileStorage::WRITE);
    storage << "camera_matrix" << cameraMatrix(preset("fisheye.yaml")[0].intrinsics);
    storage << "dist_coeffs" << cv::Mat(std::vector<double>{0.02, -0.005, 0.001, -0.0002});
    storage << "resolution" << cv::Mat(cv::Vec2i(1280, 720));
    storage << "project_matrix" << cv::Mat(projection) << "scale_xy" << cv::Mat(scale);
  };
  const std::vector<std::string> arguments{
      "--out",    (dir / "rig.yaml").string(), "--lens", "fisheye", "--canvas-scale", "1",
      "--camera", "front=" + file.string()};
  const auto refusal = [&] {
    try {
      importWith(arguments);
    } catch (const UsageError& error) {
      return std::string(error.what());
    }
    return std::string("imported");
  };
  write({1, 2, 3, 2, 4, 6, 0, 0, 1}, {1, 1});
  EXPECT_THAT(refusal(),
              AllOf(HasSubstr("front.yaml: project_matrix"), HasSubstr("cannot be inverted")));
  write(cv::Matx33d::eye(), {-0.7, 0.8});
  EXPECT_THAT(refusal(), AllOf(HasSubstr("front.yaml: scale_xy"), HasSubstr("above 0")));
}

}  // namespace
}  // namespace surroundd::calibrate
