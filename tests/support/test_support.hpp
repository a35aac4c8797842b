#pragma once
// Helpers shared by the tests: a deterministic synthetic picture, reading a whole file back through
// FileSource, a fixture that runs a body per container, and a file's bytes.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "capture/file_source.hpp"
#include "tests/support/temp_dir.hpp"

namespace surroundd::testing {

// Smooth gradients (what cameras mostly see), hard edges, and two shapes that move with `index`, so
// that consecutive frames differ and a swapped or repeated frame is caught.
inline cv::Mat syntheticPicture(cv::Size size, int index) {
  cv::Mat image(size, CV_8UC3);
  for (int y = 0; y < image.rows; ++y) {
    auto* row = image.ptr<cv::Vec3b>(y);
    for (int x = 0; x < image.cols; ++x) {
      row[x] = cv::Vec3b(static_cast<std::uint8_t>(x * 255 / size.width),
                         static_cast<std::uint8_t>(y * 255 / size.height),
                         static_cast<std::uint8_t>((x + y + index * 4) % 256));
    }
  }
  const int cx = size.width / 8 + (index * 6) % (size.width * 3 / 4);
  cv::circle(image, {cx, size.height / 2}, size.height / 8, cv::Scalar(20, 200, 240), cv::FILLED);
  const int top = size.height / 6 + (index * 3) % (size.height / 2);
  cv::rectangle(image, {size.width * 5 / 8, top}, {size.width * 13 / 16, top + size.height / 5},
                cv::Scalar(250, 40, 40), cv::FILLED);
  return image;
}

struct DecodedFile {
  std::vector<cv::Mat> images;
  std::vector<capture::Timestamp> timestamps;
  capture::ReadStatus last = capture::ReadStatus::kFrame;  // what ended the reading
};

// Reads up to `limit` frames as fast as possible; stops at the first status that is not a frame.
inline DecodedFile decodeAll(const std::filesystem::path& path, bool loop = false,
                             int limit = 10'000) {
  capture::FileSource source("test", {path, 30.0, loop, capture::Pacing::kAsFastAsPossible});
  capture::Frame frame;
  frame.image.create(source.frameSize(), CV_8UC3);
  DecodedFile decoded;
  while (limit-- > 0) {
    decoded.last = source.read(frame);
    if (decoded.last != capture::ReadStatus::kFrame) break;
    decoded.images.push_back(frame.image.clone());
    decoded.timestamps.push_back(frame.timestamp);
  }
  return decoded;
}

// Runs a test body once per container that the project writes. (Not TEST_P: its "/" in test names
// would show up in TempDir's folder names.)
class ContainerTest : public ::testing::Test {
 protected:
  template <typename Body>
  void forEachContainer(Body body) {
    for (const char* container : {".mp4", ".mkv"}) {
      SCOPED_TRACE(container);
      container_ = container;
      body();
    }
  }
  std::filesystem::path file(const std::string& stem) const { return dir_ / (stem + container_); }
  bool isMp4() const { return container_ == ".mp4"; }

  TempDir dir_;
  std::string container_;
};

inline std::string fileBytes(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(file), {}};
}

}  // namespace surroundd::testing
