// The guided calibration (surround-calibrate guide) over generated calibration sessions: a
// chessboard carried around a fisheye's and a pinhole camera's field, written as a picture
// sequence by the generator and replayed through capture's FileSource into the GuideSession, as
// the live page does. The session must pass with the focal length within 0.5 % and the principal
// point within 1 px of the truth, and say what is missing before it is there. The views and
// stream time it took are recorded (docs/calibration.md: "Guided calibration").

#include "tools/calibrate/guide/guide_session.hpp"

#include <algorithm>
#include <chrono>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "capture/file_source.hpp"
#include "tests/calibration/calibration_test_support.hpp"
#include "tests/support/temp_dir.hpp"
#include "tools/calibrate/guide/guide_state_json.hpp"
#include "tools/synth/calibration_session.hpp"

namespace surroundd::calibration::testing {
namespace {

// The generator's session: 60 frames, the board held at 12 poses, carried between them. At 4 fps
// a pose takes 1.25 s, about what a person needs to move a board and hold it still.
constexpr double kFps = 4;

calibrate::GuideSettings chessboardSettings(cv::Size corners, processing::LensModel model) {
  calibrate::GuideSettings settings;
  settings.board = {processing::BoardKind::kChessboard, corners};
  settings.model = model;
  return settings;
}

struct Replay {
  bool passed = false;
  std::size_t views = 0;
  std::chrono::nanoseconds streamTime{0};
  double wallSeconds = 0;
  std::vector<std::string> firstHints;  // after the first view was kept
  std::vector<std::string> lastUncovered;
  std::optional<calibrate::GuideSolve> solve;
  std::string lastJson;
};

Replay replay(const processing::Intrinsics& truth, std::uint64_t seed) {
  const surroundd::testing::TempDir folder;
  synth::SessionPlan plan;
  plan.seed = seed;
  synth::renderCalibrationSession(truth, plan, [&](int index, const cv::Mat& bgr) {
    ASSERT_TRUE(cv::imwrite((folder / fmt::format("frame_{:04d}.png", index)).string(), bgr));
  });
  capture::FileSource source(
      "session", {folder / "frame_%04d.png", kFps, false, capture::Pacing::kAsFastAsPossible});
  calibrate::GuideSession session(chessboardSettings(plan.board.innerCorners, truth.model));
  capture::Frame frame;
  frame.image = cv::Mat(source.frameSize(), CV_8UC3);
  cv::Mat gray;
  Replay out;
  std::optional<capture::Timestamp> start;
  const auto began = std::chrono::steady_clock::now();
  while (!session.passed() && source.read(frame) == capture::ReadStatus::kFrame) {
    if (!start) start = frame.timestamp;
    cv::cvtColor(frame.image, gray, cv::COLOR_BGR2GRAY);
    const auto result = session.offer(gray, frame.timestamp - *start);
    if (result.outcome == calibrate::FrameOutcome::kAccepted && session.views().size() == 1) {
      out.firstHints = session.hints();
    }
    out.lastJson = calibrate::guideStateJson(session, {frame.timestamp - *start, result, {}, {}});
  }
  out.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
  out.passed = session.passed();
  out.views = session.views().size();
  out.streamTime = session.passedAt();
  out.lastUncovered = session.coverage().uncoveredParts();
  out.solve = session.lastSolve();
  return out;
}

void expectPassedNearTruth(const Replay& run, const processing::Intrinsics& truth,
                           const std::string& what) {
  ASSERT_TRUE(run.passed) << what << ": " << run.lastJson.substr(run.lastJson.find("\"hints\""));
  ASSERT_TRUE(run.solve);
  const auto& lens = run.solve->result.intrinsics;
  const double fxPercent = 100 * (lens.fx / truth.fx - 1),
               fyPercent = 100 * (lens.fy / truth.fy - 1);
  EXPECT_LT(std::abs(fxPercent), 0.5) << "fx " << lens.fx << ", truth " << truth.fx;
  EXPECT_LT(std::abs(fyPercent), 0.5) << "fy " << lens.fy << ", truth " << truth.fy;
  EXPECT_NEAR(lens.cx, truth.cx, 1.0);
  EXPECT_NEAR(lens.cy, truth.cy, 1.0);
  const double streamS = std::chrono::duration<double>(run.streamTime).count();
  // What docs/calibration.md quotes.
  std::cout << fmt::format(
      "{}: passed after {} views, {:.1f} s of stream ({:.1f} s wall here); fx {:+.3f} %, fy "
      "{:+.3f} %, cx {:+.2f} px, cy {:+.2f} px, RMS {:.3f} px (sd fx {:.3f} px, cx {:.3f} px)\n",
      what, run.views, streamS, run.wallSeconds, fxPercent, fyPercent, lens.cx - truth.cx,
      lens.cy - truth.cy, run.solve->result.rmsPx, run.solve->result.uncertainty.fx,
      run.solve->result.uncertainty.cx);
  ::testing::Test::RecordProperty("views", std::to_string(run.views));
  ::testing::Test::RecordProperty("stream_s", fmt::format("{:.1f}", streamS));
  ::testing::Test::RecordProperty("fx_error_percent", fmt::format("{:.3f}", fxPercent));
  EXPECT_GE(run.views, 5U);
  EXPECT_EQ(run.solve->viewsOffered, run.views);  // it passed on the view that made it enough
  EXPECT_NE(run.lastJson.find(R"("phase": "passed")"), std::string::npos);
}

// After the first view the hints name the parts still empty, in words a user can follow, and the
// session then filled some of them: those are named no more when it passed.
void expectHintsNamedWhatWasMissing(const Replay& run) {
  std::vector<std::string> named;
  for (const auto& hint : run.firstHints) {
    for (const auto& prefix : {"tilt the board into ", "move the board to "}) {
      if (hint.starts_with(prefix)) named.push_back(hint.substr(std::string(prefix).size()));
    }
  }
  EXPECT_GE(named.size(), 4U) << fmt::format("{}", fmt::join(run.firstHints, "; "));
  EXPECT_TRUE(std::any_of(run.firstHints.begin(), run.firstHints.end(), [](const auto& h) {
    return h.find("corner") != std::string::npos && h.starts_with("tilt the board into ");
  }));
  const auto coveredSince = std::count_if(named.begin(), named.end(), [&](const auto& part) {
    return std::count(run.lastUncovered.begin(), run.lastUncovered.end(), part) == 0;
  });
  EXPECT_GE(coveredSince, 2) << "named: " << fmt::format("{}", fmt::join(named, "; "));
}

TEST(GuideSession, FisheyeSessionPassesNearTheTruth) {
  const auto truth = presetCameras("fisheye.yaml").front().intrinsics;
  const auto run = replay(truth, 4);
  expectPassedNearTruth(run, truth, "fisheye");
  expectHintsNamedWhatWasMissing(run);
}

TEST(GuideSession, PinholeSessionPassesNearTheTruth) {
  const auto truth = presetCameras("paper.yaml").front().intrinsics;
  const auto run = replay(truth, 3);
  expectPassedNearTruth(run, truth, "pinhole");
  expectHintsNamedWhatWasMissing(run);
}

// A board of another size: nothing is kept, and the state names the size as the problem.
TEST(GuideSession, WrongBoardSizeIsNamed) {
  const auto truth = presetCameras("paper.yaml").front().intrinsics;
  const processing::Checkerboard board{{9, 6}, 0.05};
  const auto pictures = boardViews(truth, board, 3, 5);
  calibrate::GuideSession session(chessboardSettings({6, 5}, truth.model));
  calibrate::FrameResult last;
  for (const auto& picture : pictures) last = session.offer(toGray(picture), {});
  EXPECT_TRUE(session.views().empty());
  EXPECT_EQ(last.outcome, calibrate::FrameOutcome::kLargerThanBoard);
  ASSERT_FALSE(session.hints().empty());
  EXPECT_NE(session.hints().front().find("larger than the 6x5 chessboard"), std::string::npos)
      << session.hints().front();
}

}  // namespace
}  // namespace surroundd::calibration::testing
