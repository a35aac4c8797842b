#pragma once
// Looking for the board in many pictures at once, each within a bound of CPU time, with progress.
//
// OpenCV's chessboard detectors cannot be interrupted, and on a picture of a board of another size
// the exhaustive search can run for minutes. Each picture is searched on a worker thread; one that
// passes its bound is reported as timed out and its thread is left to finish on its own (detached,
// owning everything it touches: its picture, a copy of the board, the shared results), while a
// new worker takes its place. A wrong board size is refused early: once a few pictures show a grid
// larger than the board named and none shows the board, the search stops.
//
// The same pictures give the same results whatever the machine's load: the bound counts the CPU
// time of the search's own thread, not the wall clock (under load, pictures once dropped out at
// random and one command gave different lenses from run to run), OpenCV's own threads are off
// meanwhile so that all the search's work is on that thread, and the early stop looks at the
// pictures in index order, not in the order the threads finish.

#include <chrono>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/calibration/calibration_board.hpp"

namespace surroundd::processing {

struct PictureSearch {
  enum class Outcome { kFound, kNotFound, kLargerThanBoard, kTimedOut, kNotSearched, kUnreadable };
  Outcome outcome = Outcome::kNotSearched;
  cv::Size imageSize;
  std::vector<cv::Point2f> corners;  // kFound
  std::vector<cv::Point> grid;       // kFound
  cv::Size seenGrid;                 // kLargerThanBoard: the grid found
  double edgeWidthPx = 0;            // kFound: see view_acceptance.hpp
  double seconds = 0;                // the CPU time the search took
};

struct SearchOptions {
  int threads = 0;                              // 0: one per core
  std::chrono::milliseconds perPicture{10000};  // of the searching thread's CPU time
  // This many pictures with a larger grid, and none with the board: the size is wrong; stop.
  int largerGridsToStop = 3;
};

// Reads picture `index` as CV_8U gray; an empty Mat when it cannot. Called on worker threads, at
// most once per index, before that picture's time bound starts; must be safe to call concurrently.
using PictureLoader = std::function<cv::Mat(std::size_t index)>;
// Called on the caller's thread as each picture is done, in the order they finish.
using SearchProgress =
    std::function<void(std::size_t index, const PictureSearch& result, std::size_t done)>;

// One result per picture, in index order.
std::vector<PictureSearch> searchPictures(std::size_t count, PictureLoader loader,
                                          const CalibrationBoard& board,
                                          const SearchOptions& options,
                                          const SearchProgress& progress);

}  // namespace surroundd::processing
