// StageTimes: where the pipeline thread's time goes, per stage and per frame set.

#include "daemon/stage_times.hpp"

#include <chrono>
#include <thread>

#include <gtest/gtest.h>

namespace surroundd::daemon {
namespace {

using std::chrono::milliseconds;

std::size_t index(Stage stage) { return static_cast<std::size_t>(stage); }

TEST(StageTimes, ASetsStagesGoToTheirHistogramsAndADroppedSetOnlyToTheSums) {
  StageTimes times;
  // Waiting without a set counts towards the next set's sync.
  times.waited(milliseconds(2));
  times.waited(milliseconds(1));
  times.beginSet();
  std::this_thread::sleep_for(milliseconds(2));
  times.lap(Stage::kStitch);
  times.skip();
  times.lap(Stage::kCorrect);
  times.endSet();

  const auto& histograms = times.histograms();
  EXPECT_EQ(histograms[index(Stage::kSync)].count(), 1U);
  EXPECT_EQ(histograms[index(Stage::kSync)].sum(), milliseconds(3));
  EXPECT_EQ(histograms[index(Stage::kStitch)].count(), 1U);
  EXPECT_GE(histograms[index(Stage::kStitch)].sum(), milliseconds(2));
  EXPECT_EQ(histograms[index(Stage::kCorrect)].count(), 1U);
  EXPECT_LT(histograms[index(Stage::kCorrect)].sum(), milliseconds(2));  // the sleep was skipped
  EXPECT_EQ(histograms[index(Stage::kMosaic)].count(), 0U);  // a stage the set did not go through

  times.waited(milliseconds(4));
  times.beginSet();
  times.lap(Stage::kStitch);
  times.dropSet();
  EXPECT_EQ(histograms[index(Stage::kSync)].count(), 1U);
  EXPECT_EQ(histograms[index(Stage::kStitch)].count(), 1U);
  EXPECT_EQ(times.totals()[index(Stage::kSync)], milliseconds(7));

  // The next set starts from nothing: the dropped one's times are not carried over.
  times.beginSet();
  times.endSet();
  EXPECT_EQ(histograms[index(Stage::kSync)].count(), 2U);
  EXPECT_EQ(histograms[index(Stage::kSync)].sum(), milliseconds(3));
}

}  // namespace
}  // namespace surroundd::daemon
