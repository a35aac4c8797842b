#pragma once
// What calibration throws when the data cannot give an answer (too few views or points, a solver
// that does not converge); the message says what was found and what is needed.

#include <stdexcept>

namespace surroundd::processing {

class CalibrationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace surroundd::processing
