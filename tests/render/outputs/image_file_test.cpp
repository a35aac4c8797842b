// Snapshots as PNG (render/outputs/image_file.hpp): what FFmpeg's encoder writes decodes, through
// OpenCV's own reader, to the same pixels; a file is written whole or, when it cannot be, not at
// all.

#include "render/outputs/image_file.hpp"

#include <filesystem>
#include <stdexcept>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "tests/support/temp_dir.hpp"

namespace surroundd::render {
namespace {

cv::Mat testPicture() {
  cv::Mat picture(181, 321, CV_8UC3);  // odd sides: rows of no aligned length
  cv::randu(picture, 0, 256);
  picture(cv::Rect(0, 0, 100, 100)).setTo(cv::Scalar(10, 200, 30));  // B, G, R kept apart
  return picture;
}

TEST(ImageFile, APngHoldsThePictureExactly) {
  const cv::Mat picture = testPicture();
  const std::vector<std::uint8_t> png = encodePng(picture);
  ASSERT_GT(png.size(), 8U);
  EXPECT_EQ(cv::norm(cv::imdecode(png, cv::IMREAD_UNCHANGED), picture, cv::NORM_INF), 0.0);
  EXPECT_THROW((void)encodePng(cv::Mat(4, 4, CV_8UC1)), std::invalid_argument);
}

TEST(ImageFile, AFileIsWrittenWholeOrNotAtAll) {
  const testing::TempDir dir;
  const cv::Mat picture = testPicture();
  writeImageFile(dir / "snapshot.png", picture);
  EXPECT_EQ(cv::norm(cv::imread((dir / "snapshot.png").string()), picture, cv::NORM_INF), 0.0);
  EXPECT_FALSE(std::filesystem::exists(dir / "snapshot.png.part"));
  // A folder that is not there: the error names the file, and nothing is left.
  try {
    writeImageFile(dir / "nowhere" / "snapshot.png", picture);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nowhere/snapshot.png"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "nowhere"));
}

}  // namespace
}  // namespace surroundd::render
