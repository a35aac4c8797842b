#include "tools/calibrate/guide/guide_session.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>
#include <opencv2/core.hpp>

#include "processing/calibration/calibration_error.hpp"
#include "processing/calibration/view_acceptance.hpp"
#include "tools/calibrate/lens_field.hpp"

namespace surroundd::calibrate {
namespace {

// "the top left corner" -> "tilt the board into the top left corner"; an edge or the centre is
// reached by moving the board, a corner (where a fisheye squeezes it) by tilting it in.
std::string hintFor(const std::string& part) {
  const bool corner = part.find("corner") != std::string::npos;
  return fmt::format("{} the board {} {}", corner ? "tilt" : "move", corner ? "into" : "to", part);
}

}  // namespace

GuideSession::GuideSession(const GuideSettings& settings) : settings_(settings) {
  auto& limits = settings_.limits;
  limits.maxFocalSdPercent = std::min(limits.maxFocalSdPercent, kGuideFocalSdPercent);
  limits.maxPrincipalSdPx = std::min(limits.maxPrincipalSdPx, kGuidePrincipalSdPx);
}

FrameResult GuideSession::offer(const cv::Mat& gray, std::chrono::nanoseconds streamTime) {
  if (imageSize_.area() == 0) {
    imageSize_ = gray.size();
    brightest_ = gray.clone();
    circle_ = lensCircle(settings_.model, brightest_);
    coverage_ = processing::coverageOf({}, imageSize_, circle_.lit);
  } else if (gray.size() != imageSize_) {
    throw std::invalid_argument(
        fmt::format("the camera's picture changed from {}x{} to {}x{}: one camera, one resolution",
                    imageSize_.width, imageSize_.height, gray.cols, gray.rows));
  } else if (!passed()) {
    cv::max(brightest_, gray, brightest_);
  }
  ++frames_;
  FrameResult out;
  const auto search = processing::findBoard(gray, settings_.board);
  if (search.outcome == processing::BoardSearch::Outcome::kLargerThanBoard) {
    if (views_.empty()) {
      sizeProblem_ = fmt::format(
          "the camera shows a {}x{} chessboard grid, larger than the {} named: the board size is "
          "wrong (--board counts inner corners, where four squares meet)",
          search.seenGrid.width, search.seenGrid.height, settings_.board.describe());
    }
    out.outcome = FrameOutcome::kLargerThanBoard;
    out.note = sizeProblem_;
    return out;
  }
  if (search.outcome != processing::BoardSearch::Outcome::kFound) {
    out.note = fmt::format("no {} in the picture", settings_.board.describe());
    return out;
  }
  sizeProblem_.clear();
  out.corners = search.corners;
  if (passed()) {
    out.outcome = FrameOutcome::kDone;
    out.note = "the lens passed; nothing more is needed";
    return out;
  }
  GuideView candidate{{fmt::format("view {}", views_.size() + 1), search.corners, search.grid},
                      streamTime};
  candidate.view.edgeWidthPx = processing::edgeWidthPx(gray, candidate.view);
  if (const auto blurred = processing::blurProblem(candidate.view, settings_.limits)) {
    out.outcome = FrameOutcome::kBlurred;
    out.note = fmt::format("{} (hold the board still)", *blurred);
    return out;
  }
  std::vector<processing::BoardView> boards;
  boards.reserve(views_.size() + 1);
  for (const auto& v : views_) boards.push_back(v.view);
  boards.push_back(candidate.view);
  for (const auto& d : processing::findDuplicateViews(boards, settings_.repeatOverlap)) {
    if (d.view == views_.size()) {
      out.outcome = FrameOutcome::kRepeat;
      out.note = fmt::format("the board is where {} was ({:.0f} % overlap): move or tilt it",
                             views_[d.of].view.name, 100 * d.overlap);
      return out;
    }
  }
  views_.push_back(std::move(candidate));
  circle_ = lensCircle(settings_.model, brightest_);
  boards.back() = views_.back().view;
  coverage_ = processing::coverageOf(boards, imageSize_, circle_.lit);
  out.outcome = FrameOutcome::kAccepted;
  out.note = fmt::format("kept {} ({} corners); coverage {:.0f} %", views_.back().view.name,
                         out.corners.size(), 100 * coverage_.coveredShare);
  if (enoughToSolve()) solve(streamTime);
  return out;
}

bool GuideSession::enoughToSolve() const {
  return static_cast<int>(views_.size()) >= settings_.limits.minViews &&
         coverage_.coveredShare >= settings_.limits.minCoverage;
}

void GuideSession::solve(std::chrono::nanoseconds streamTime) {
  std::vector<processing::BoardView> boards;
  boards.reserve(views_.size());
  for (const auto& v : views_) boards.push_back(v.view);
  GuideSolve solved;
  solved.viewsOffered = views_.size();
  try {
    auto robust = processing::calibrateLeavingOutBadViews(settings_.model, imageSize_, boards,
                                                          settings_.limits);
    solved.result = std::move(robust.result);
    solved.leftOut = std::move(robust.leftOut);
  } catch (const processing::CalibrationError& error) {
    // Not a lens yet: say why and keep collecting.
    solved.verdict = {false, {fmt::format("the solve failed: {}", error.what())}, {}};
    solve_ = std::move(solved);
    return;
  }
  solved.field = limitField(solved.result.intrinsics, circle_, boards, settings_.fieldOfViewDeg);
  solved.verdict =
      processing::judgeCalibration(solved.result, coverage_.coveredShare, settings_.limits);
  solve_ = std::move(solved);
  if (solve_->verdict.passed) passedAt_ = streamTime;
}

std::vector<std::string> GuideSession::hints() const {
  if (passed()) return {"the lens passed: its lens block is written"};
  std::vector<std::string> hints;
  if (!sizeProblem_.empty()) hints.push_back(sizeProblem_);
  if (views_.empty()) {
    hints.push_back(
        fmt::format("hold the {} up in front of the camera", settings_.board.describe()));
  }
  for (const auto& part : coverage_.uncoveredParts()) hints.push_back(hintFor(part));
  const int missing = settings_.limits.minViews - static_cast<int>(views_.size());
  if (missing > 0 && !views_.empty()) {
    hints.push_back(
        fmt::format("{} more view{} at other angles", missing, missing == 1 ? "" : "s"));
  }
  if (!views_.empty() && coverage_.coveredShare < settings_.limits.minCoverage) {
    hints.push_back(
        fmt::format("cover more of the picture: corners in {:.0f} % of it, {:.0f} % "
                    "needed",
                    100 * coverage_.coveredShare, 100 * settings_.limits.minCoverage));
  }
  if (solve_) {
    for (const auto& failure : solve_->verdict.failures) hints.push_back(failure);
    hints.emplace_back("keep moving the board: each new view solves again");
  }
  return hints;
}

}  // namespace surroundd::calibrate
