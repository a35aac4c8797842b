#include "tools/calibrate/guide/guide_state_json.hpp"

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

namespace surroundd::calibrate {
namespace {

double seconds(std::chrono::nanoseconds t) { return std::chrono::duration<double>(t).count(); }

const char* outcomeName(FrameOutcome outcome) {
  switch (outcome) {
    case FrameOutcome::kAccepted:
      return "accepted";
    case FrameOutcome::kNoBoard:
      return "no board";
    case FrameOutcome::kLargerThanBoard:
      return "larger grid";
    case FrameOutcome::kBlurred:
      return "blurred";
    case FrameOutcome::kRepeat:
      return "repeat";
    case FrameOutcome::kDone:
      return "done";
  }
  return "?";
}

// The board's outline in the picture: the hull of its corners, enough for the page to draw it.
std::string outlineJson(const std::vector<cv::Point2f>& corners) {
  std::vector<cv::Point2f> hull;
  cv::convexHull(corners, hull);
  std::string json = "[";
  for (std::size_t i = 0; i < hull.size(); ++i) {
    json += fmt::format("{}[{:.1f}, {:.1f}]", i ? ", " : "", hull[i].x, hull[i].y);
  }
  return json + "]";
}

std::string coverageJson(const processing::CoverageMap& map, double needed) {
  std::string cells;
  for (int row = 0; row < map.cells.height; ++row) {
    for (int column = 0; column < map.cells.width; ++column) {
      const int count = map.inLens.at<std::uint8_t>(row, column) == 0
                            ? -1
                            : map.cornerCounts.at<int>(row, column);
      cells += fmt::format("{}{}", cells.empty() ? "" : ", ", count);
    }
  }
  return fmt::format(
      R"({{"columns": {}, "rows": {}, "share": {:.4f}, "needed": {:.4f}, "cells": [{}]}})",
      map.cells.width, map.cells.height, map.coveredShare, needed, cells);
}

std::string verdictJson(const GuideSolve& solve) {
  const auto& lens = solve.result.intrinsics;
  return fmt::format(
      R"({{"passed": {}, "failures": {}, "rmsPx": {:.4f}, "fx": {:.3f}, "fy": {:.3f}, )"
      R"("cx": {:.3f}, "cy": {:.3f}, "views": {}, "leftOut": {}, "fieldOfViewDeg": {:.1f}}})",
      solve.verdict.passed, jsonStringArray(solve.verdict.failures), solve.result.rmsPx, lens.fx,
      lens.fy, lens.cx, lens.cy, solve.result.views.size(), jsonStringArray(solve.leftOut),
      solve.field.fullDeg);
}

}  // namespace

std::string jsonString(std::string_view text) {
  std::string json = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      json += '\\';
      json += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      json += fmt::format("\\u{:04x}", static_cast<int>(c));
    } else {
      json += c;
    }
  }
  return json + "\"";
}

std::string jsonStringArray(const std::vector<std::string>& items) {
  std::string json = "[";
  for (std::size_t i = 0; i < items.size(); ++i) json += (i ? ", " : "") + jsonString(items[i]);
  return json + "]";
}

std::string guideStateJson(const GuideSession& session, const GuideRunState& run) {
  const auto& settings = session.settings();
  std::string views = "[";
  for (std::size_t i = 0; i < session.views().size(); ++i) {
    const auto& v = session.views()[i];
    views += fmt::format(
        R"({}{{"name": {}, "timeS": {:.3f}, "corners": {}, "edgePx": {:.2f}, "outline": {}}})",
        i ? ", " : "", jsonString(v.view.name), seconds(v.streamTime), v.view.corners.size(),
        v.view.edgeWidthPx, outlineJson(v.view.corners));
  }
  views += "]";
  const char* phase = session.passed() ? "passed" : run.ended ? "ended" : "collecting";
  const auto& solve = session.lastSolve();
  return fmt::format(
      R"({{"phase": "{}", "board": {}, "model": "{}", "image": {{"width": {}, "height": {}}}, )"
      R"("frames": {}, "streamTimeS": {:.3f}, "views": {}, "coverage": {}, "minViews": {}, )"
      R"("hints": {}, "last": {{"outcome": "{}", "note": {}}}, "verdict": {}, "passedAtS": {}, )"
      R"("written": {}, "error": {}}})",
      phase, jsonString(settings.board.describe()), processing::lensModelName(settings.model),
      session.imageSize().width, session.imageSize().height, session.framesOffered(),
      seconds(run.streamTime), views,
      session.imageSize().area() > 0 ? coverageJson(session.coverage(), settings.limits.minCoverage)
                                     : "null",
      settings.limits.minViews, jsonStringArray(session.hints()), outcomeName(run.last.outcome),
      jsonString(run.last.note), solve ? verdictJson(*solve) : "null",
      session.passed() ? fmt::format("{:.3f}", seconds(session.passedAt())) : "null",
      jsonStringArray(run.written), jsonString(run.error));
}

}  // namespace surroundd::calibrate
