#pragma once
// Runs the surround-calibrate executable (SURROUND_CALIBRATE, set by the test's target) in a test's
// folder and keeps what it printed.

#include <string>
#include <vector>

#include "tests/support/child_process.hpp"
#include "tests/support/temp_dir.hpp"

namespace surroundd::calibration::testing {

struct CalibrateRun {
  int status;
  std::string output;
};

inline CalibrateRun calibrate(const surroundd::testing::TempDir& dir,
                              std::vector<std::string> arguments) {
  arguments.insert(arguments.begin(), SURROUND_CALIBRATE);
  surroundd::testing::ChildProcess child(arguments, dir / "log.txt");
  const int status = child.wait();
  return {status, child.output()};
}

}  // namespace surroundd::calibration::testing
