#include "tools/calibrate/extrinsics/mat_report.hpp"

#include <algorithm>

#include <fmt/format.h>

namespace surroundd::calibrate {

void printMatReport(const processing::MatLayout& mat, const processing::MatCalibration& result,
                    std::ostream& log) {
  log << fmt::format("{:<10} {:>7} {:>8} {:>8} {:>10} {:>9}  {}\n", "camera", "boards", "corners",
                     "RMS px", "moved cm", "turn deg", "verdict");
  for (const auto& camera : result.cameras) {
    const std::size_t expected = camera.detection.found.size() + camera.detection.missed.size();
    const auto& solve = camera.solve;
    log << fmt::format("{:<10} {:>7} {:>8} {:>8} {:>10} {:>9}  {}\n", camera.camera,
                       fmt::format("{}/{}", camera.detection.found.size(), expected),
                       camera.corners, solve ? fmt::format("{:.3f}", solve->rmsPx) : "-",
                       solve ? fmt::format("{:.1f}", 100 * camera.shiftM) : "-",
                       solve ? fmt::format("{:.2f}", camera.turnDeg) : "-",
                       camera.passed() ? "ok" : "FAILED");
    for (const auto& board : camera.boards) {
      const auto& sighting =
          *std::find_if(camera.detection.found.begin(), camera.detection.found.end(),
                        [&](const auto& s) { return s.board == board.board; });
      log << fmt::format(
          "    board {:<16} {:>4} corners, RMS {:.3f} px{}\n", mat.boards[board.board].print.name,
          board.corners, board.rmsPx,
          sighting.orientedByNominalPose ? " (symmetric: oriented by the rig's mount)" : "");
    }
    for (const auto& problem : camera.problems) log << "    problem: " << problem << "\n";
  }
  if (!result.seams.empty()) {
    log << "seams (ground distance between where two cameras put a shared board's corners):\n";
  }
  for (const auto& seam : result.seams) {
    log << fmt::format("  {:<16} board {:<16} RMS {:.2f} cm, max {:.2f} cm\n",
                       fmt::format("{}|{}", seam.first, seam.second),
                       mat.boards[seam.board].print.name, seam.rmsCm, seam.maxCm);
  }
  for (const auto& problem : result.problems) log << "problem: " << problem << "\n";
}

}  // namespace surroundd::calibrate
