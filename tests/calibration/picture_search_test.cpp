// searchPictures() (processing/calibration/picture_search.hpp) gives the same results for the
// same pictures whatever else the machine is doing (issue 47: the same intrinsics command once
// gave different lenses under load, as a wall-clock bound dropped pictures at random).

#include "processing/calibration/picture_search.hpp"

#include <algorithm>
#include <atomic>
#include <stop_token>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "tests/calibration/board_views_support.hpp"

namespace surroundd::calibration::testing {
namespace {

std::vector<processing::PictureSearch> search(const std::vector<cv::Mat>& pictures,
                                              const processing::CalibrationBoard& board,
                                              std::chrono::milliseconds perPicture) {
  processing::SearchOptions options;
  options.perPicture = perPicture;
  return processing::searchPictures(pictures.size(),
                                    [&](std::size_t index) { return toGray(pictures[index]); },
                                    board, options, {});
}

TEST(PictureSearch, TheSamePicturesCountWhateverTheLoad) {
  const auto board = chessboard(9, 6);
  const auto lens = presetCameras("fisheye.yaml").front().intrinsics;
  std::vector<cv::Mat> pictures = anyBoardViews(lens, board, 4, 21, 100);
  // And one with no board, whose search is the longest for its size: every detector tries it in
  // full (a quarter of the others' size keeps the test short).
  cv::Mat noise(pictures.front().size() / 2, pictures.front().type());
  cv::randu(noise, 0, 256);
  pictures.push_back(noise);

  // Alone, with room to spare: how long each search takes on this machine, in CPU time.
  const auto alone = search(pictures, board, std::chrono::minutes(10));
  double longest = 0;
  for (const auto& result : alone) {
    ASSERT_NE(result.outcome, processing::PictureSearch::Outcome::kTimedOut);
    longest = std::max(longest, result.seconds);
  }
  EXPECT_GE(std::ranges::count(alone, processing::PictureSearch::Outcome::kFound,
                               &processing::PictureSearch::outcome),
            3);

  // Again with a bound of twice the longest search, while six busy threads a core take most of
  // the machine: a search takes several times as long on the wall clock, and no longer in CPU
  // time. The same pictures count, with the same corners.
  const auto bound = std::chrono::milliseconds(static_cast<long long>(2000 * longest) + 50);
  std::vector<processing::PictureSearch> loaded;
  {
    std::vector<std::jthread> busy;
    const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    for (unsigned k = 0; k < 6 * cores; ++k) {
      busy.emplace_back([](const std::stop_token& stop) {
        std::atomic<unsigned> spin{0};
        while (!stop.stop_requested()) spin.fetch_add(1, std::memory_order_relaxed);
      });
    }
    loaded = search(pictures, board, bound);
  }
  ASSERT_EQ(loaded.size(), alone.size());
  for (std::size_t i = 0; i < alone.size(); ++i) {
    EXPECT_EQ(loaded[i].outcome, alone[i].outcome) << "picture " << i;
    EXPECT_EQ(loaded[i].corners, alone[i].corners) << "picture " << i;
  }
}

}  // namespace
}  // namespace surroundd::calibration::testing
