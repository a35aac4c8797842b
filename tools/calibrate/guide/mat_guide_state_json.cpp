#include "tools/calibrate/guide/mat_guide_state_json.hpp"

#include <fmt/format.h>

#include "tools/calibrate/guide/guide_state_json.hpp"

namespace surroundd::calibrate {
namespace {

std::string cameraJson(const MatGuideSession& session, std::size_t c) {
  const auto& name = session.settings().cameras[c].name;
  const int frames = session.framesOffered()[c];
  const auto& result = session.result();
  if (!result) {
    return fmt::format(
        R"({{"name": {}, "frames": {}, "boardsFound": 0, "boardsExpected": {}, "corners": 0, )"
        R"("rmsPx": null, "movedCm": null, "turnDeg": null, "passed": null, "problems": []}})",
        jsonString(name), frames, processing::boardsSeenBy(session.settings().mat, name).size());
  }
  const auto& camera = result->cameras[c];
  const auto& solve = camera.solve;
  return fmt::format(
      R"({{"name": {}, "frames": {}, "boardsFound": {}, "boardsExpected": {}, "corners": {}, )"
      R"("rmsPx": {}, "movedCm": {}, "turnDeg": {}, "passed": {}, "problems": {}}})",
      jsonString(name), frames, camera.detection.found.size(),
      camera.detection.found.size() + camera.detection.missed.size(), camera.corners,
      solve ? fmt::format("{:.4f}", solve->rmsPx) : "null",
      solve ? fmt::format("{:.2f}", 100 * camera.shiftM) : "null",
      solve ? fmt::format("{:.3f}", camera.turnDeg) : "null", camera.passed(),
      jsonStringArray(camera.problems));
}

std::string seamsJson(const MatGuideSession& session) {
  std::string json = "[";
  const auto& result = session.result();
  if (!result) return json + "]";
  const double limit = session.settings().limits.maxSeamCm;
  for (std::size_t i = 0; i < result->seams.size(); ++i) {
    const auto& seam = result->seams[i];
    json += fmt::format(
        R"({}{{"board": {}, "cameras": {}, "corners": {}, "rmsCm": {:.3f}, "maxCm": {:.3f}, )"
        R"("passed": {}}})",
        i ? ", " : "", jsonString(session.settings().mat.boards[seam.board].print.name),
        jsonString(seam.first + "|" + seam.second), seam.corners, seam.rmsCm, seam.maxCm,
        seam.rmsCm <= limit);
  }
  return json + "]";
}

}  // namespace

std::string matGuideStateJson(const MatGuideSession& session, const MatGuideRunState& run) {
  const auto& result = session.result();
  const char* phase = session.passed() ? "passed"
                      : run.ended      ? "ended"
                      : result         ? "failed"
                                       : "waiting";
  std::string cameras = "[";
  for (std::size_t c = 0; c < session.settings().cameras.size(); ++c) {
    cameras += (c ? ", " : "") + cameraJson(session, c);
  }
  cameras += "]";
  std::string verdict = "null";
  if (result) {
    std::size_t failures = result->problems.size();
    for (const auto& camera : result->cameras) failures += camera.problems.size();
    verdict = fmt::format(R"({{"passed": {}, "failures": {}}})", result->passed(), failures);
  }
  return fmt::format(
      R"({{"phase": "{}", "solves": {}, "seamLimitCm": {:g}, "cameras": {}, "seams": {}, )"
      R"("problems": {}, "hints": {}, "verdict": {}, "written": {}, "error": {}}})",
      phase, session.solves(), session.settings().limits.maxSeamCm, cameras, seamsJson(session),
      jsonStringArray(result ? result->problems : std::vector<std::string>{}),
      jsonStringArray(session.hints()), verdict, jsonStringArray(run.written),
      jsonString(run.error));
}

}  // namespace surroundd::calibrate
