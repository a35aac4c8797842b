// The clock a replay is paced by: a rig's replayed cameras share where it starts, so that their
// frames of one instant are due together however far apart each camera reads its first, and each
// frame is due exactly its timestamp's distance from the first frame read.

#include "capture/replay_clock.hpp"

#include <array>
#include <chrono>
#include <thread>

#include <gtest/gtest.h>

namespace surroundd::capture {
namespace {

using std::chrono::milliseconds;

TEST(ReplayStart, EachFrameIsDueItsTimestampsDistanceFromTheFirstRead) {
  ReplayStart start;
  const auto before = ReplayStart::Clock::now();
  const auto first = start.due(milliseconds(5000));
  EXPECT_GE(first, before);
  EXPECT_LE(first, ReplayStart::Clock::now());
  EXPECT_EQ(start.due(milliseconds(5033)), first + milliseconds(33));
  EXPECT_EQ(start.due(milliseconds(6000)), first + milliseconds(1000));
  // A frame stamped before the first one read is already due.
  EXPECT_EQ(start.due(milliseconds(4990)), first - milliseconds(10));
}

// Four cameras, each on its thread, reading their first frames 20 ms apart: all four are due at
// the instant the first was read, and so are their later frames of one timestamp.
TEST(ReplayStart, TheCamerasOfARigAreDueTogetherHoweverLateTheyStart) {
  ReplayStart start;
  std::array<ReplayStart::Clock::time_point, 4> firstDue;
  std::array<ReplayStart::Clock::time_point, 4> laterDue;
  for (std::size_t c = 0; c < firstDue.size(); ++c) {
    std::thread camera([&, c] {
      // Stamps 1 ms apart, as the cameras of a rig that is not triggered together.
      firstDue[c] = start.due(milliseconds(100 + static_cast<int>(c)));
      laterDue[c] = start.due(milliseconds(200));
    });
    camera.join();
    std::this_thread::sleep_for(milliseconds(20));
  }
  for (std::size_t c = 1; c < firstDue.size(); ++c) {
    EXPECT_EQ(firstDue[c], firstDue[0] + milliseconds(c)) << c;
    EXPECT_EQ(laterDue[c], laterDue[0]) << c;
  }
  EXPECT_EQ(laterDue[0], firstDue[0] + milliseconds(100));
}

// Without a start handed to it, a pacer keeps its own: the first frame it reads is due at once,
// whatever another pacer started from.
TEST(ReplayPacer, APacerWithoutASharedStartStartsAtItsFirstFrame) {
  ReplayPacer other(Pacing::kRealtime);
  other.waitFor(milliseconds(0));
  ReplayPacer own(Pacing::kRealtime);
  const auto before = ReplayStart::Clock::now();
  own.waitFor(milliseconds(50'000));  // its first: due now, not 50 s after the other's
  EXPECT_LT(ReplayStart::Clock::now() - before, std::chrono::seconds(10));
}

}  // namespace
}  // namespace surroundd::capture
