#pragma once
// The matrix of a PoissonSystem in rows (diagonal = degree, -1 for each unknown neighbour),
// checked for consistency once; and the residual |b - A x| / |b| that the direct solvers report.

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "processing/colour/poisson_system.hpp"

namespace surroundd::processing {

class PoissonMatrix {
 public:
  // Throws std::invalid_argument when the system is inconsistent: sizes that differ, a pixel
  // outside `size` or twice, a link that is not between 4-neighbours or is given twice, two
  // neighbouring unknowns without their link, a degree below the unknown neighbours or above 4.
  explicit PoissonMatrix(const PoissonSystem& system);

  std::size_t unknowns() const { return degree_.size(); }
  int degree(std::size_t i) const { return degree_[i]; }
  // The unknowns next to unknown i (its -1 entries), in increasing order.
  std::span<const std::int32_t> neighbours(std::size_t i) const {
    return {neighbours_.data() + rowBegin_[i], neighbours_.data() + rowBegin_[i + 1]};
  }

  // An unknown in a part of the region that no Dirichlet neighbour reaches (where the matrix is
  // singular), or none.
  std::optional<std::size_t> floatingUnknown() const;

  // |b - A x| / |b| over the three interleaved channels (index 3 * i + c), in double; |A x| when
  // b = 0. Allocates nothing.
  double relativeResidual(std::span<const float> rhs, std::span<const float> x) const;

 private:
  std::vector<std::int32_t> degree_;
  std::vector<std::uint32_t> rowBegin_;  // neighbours of i: [rowBegin_[i], rowBegin_[i + 1])
  std::vector<std::int32_t> neighbours_;
};

// Throws std::invalid_argument unless rhs and x both hold 3 values per unknown.
void checkChannelSpans(std::size_t unknowns, std::size_t rhsSize, std::size_t xSize);

}  // namespace surroundd::processing
