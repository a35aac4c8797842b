#include "processing/colour/poisson_matrix.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include <fmt/format.h>

namespace surroundd::processing {

PoissonMatrix::PoissonMatrix(const PoissonSystem& system) {
  const std::size_t n = system.unknowns();
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("Poisson system: " + what);
  };
  if (system.degree.size() != n) {
    fail(fmt::format("{} degrees for {} unknowns", system.degree.size(), n));
  }
  if (n == 0) fail("no unknowns");
  if (n > static_cast<std::size_t>(INT32_MAX / 4)) fail(fmt::format("{} unknowns", n));
  const cv::Size size = system.size;
  // Which unknown sits on each pixel of the region's frame, to find neighbours that miss a link.
  std::vector<std::int32_t> unknownAt(static_cast<std::size_t>(std::max(size.area(), 0)), -1);
  for (std::size_t i = 0; i < n; ++i) {
    const cv::Point p = system.pixels[i];
    if (p.x < 0 || p.y < 0 || p.x >= size.width || p.y >= size.height) {
      fail(fmt::format("unknown {} at ({}, {}) is outside the {}x{} frame", i, p.x, p.y, size.width,
                       size.height));
    }
    auto& slot = unknownAt[static_cast<std::size_t>(p.y) * size.width + p.x];
    if (slot >= 0) fail(fmt::format("unknowns {} and {} share pixel ({}, {})", slot, i, p.x, p.y));
    slot = static_cast<std::int32_t>(i);
  }

  std::vector<std::int32_t> count(n, 0);
  for (const auto& [i, j] : system.links) {
    if (i < 0 || j < 0 || static_cast<std::size_t>(i) >= n || static_cast<std::size_t>(j) >= n ||
        i >= j) {
      fail(fmt::format("link ({}, {}) is not a pair i < j of unknowns", i, j));
    }
    const cv::Point d =
        system.pixels[static_cast<std::size_t>(j)] - system.pixels[static_cast<std::size_t>(i)];
    if (std::abs(d.x) + std::abs(d.y) != 1) {
      fail(fmt::format("link ({}, {}) joins pixels that are not 4-neighbours", i, j));
    }
    ++count[static_cast<std::size_t>(i)];
    ++count[static_cast<std::size_t>(j)];
  }
  rowBegin_.assign(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    rowBegin_[i + 1] = rowBegin_[i] + static_cast<std::uint32_t>(count[i]);
  }
  neighbours_.resize(rowBegin_[n]);
  std::vector<std::uint32_t> fill(rowBegin_.begin(), rowBegin_.end() - 1);
  for (const auto& [i, j] : system.links) {
    neighbours_[fill[static_cast<std::size_t>(i)]++] = j;
    neighbours_[fill[static_cast<std::size_t>(j)]++] = i;
  }

  degree_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    auto row = std::span(neighbours_).subspan(rowBegin_[i], rowBegin_[i + 1] - rowBegin_[i]);
    std::ranges::sort(row);
    if (std::ranges::adjacent_find(row) != row.end()) {
      fail(fmt::format("unknown {} has a link given twice", i));
    }
    // Every unknown 4-neighbour must be linked: count them on the grid.
    const cv::Point p = system.pixels[i];
    std::size_t gridNeighbours = 0;
    for (const cv::Point d :
         {cv::Point(-1, 0), cv::Point(1, 0), cv::Point(0, -1), cv::Point(0, 1)}) {
      const cv::Point q = p + d;
      if (q.x >= 0 && q.y >= 0 && q.x < size.width && q.y < size.height &&
          unknownAt[static_cast<std::size_t>(q.y) * size.width + q.x] >= 0) {
        ++gridNeighbours;
      }
    }
    if (gridNeighbours != row.size()) {
      fail(fmt::format("unknown {} at ({}, {}) has {} unknown neighbours but {} links", i, p.x, p.y,
                       gridNeighbours, row.size()));
    }
    const int degree = system.degree[i];
    if (degree < static_cast<int>(row.size()) || degree > 4) {
      fail(fmt::format("unknown {} has degree {} with {} unknown neighbours", i, degree,
                       row.size()));
    }
    degree_[i] = degree;
  }
}

std::optional<std::size_t> PoissonMatrix::floatingUnknown() const {
  // Flood from every unknown with a Dirichlet neighbour; what stays dry floats.
  std::vector<bool> reached(unknowns(), false);
  std::vector<std::int32_t> frontier;
  for (std::size_t i = 0; i < unknowns(); ++i) {
    if (degree_[i] > static_cast<int>(rowBegin_[i + 1] - rowBegin_[i])) {
      reached[i] = true;
      frontier.push_back(static_cast<std::int32_t>(i));
    }
  }
  while (!frontier.empty()) {
    const auto i = static_cast<std::size_t>(frontier.back());
    frontier.pop_back();
    for (const std::int32_t j : neighbours(i)) {
      if (!reached[static_cast<std::size_t>(j)]) {
        reached[static_cast<std::size_t>(j)] = true;
        frontier.push_back(j);
      }
    }
  }
  const auto dry = std::ranges::find(reached, false);
  if (dry == reached.end()) return std::nullopt;
  return static_cast<std::size_t>(dry - reached.begin());
}

double PoissonMatrix::relativeResidual(std::span<const float> rhs, std::span<const float> x) const {
  checkChannelSpans(unknowns(), rhs.size(), x.size());
  double residualSquared = 0;
  double rhsSquared = 0;
  for (std::size_t i = 0; i < unknowns(); ++i) {
    for (std::size_t c = 0; c < 3; ++c) {
      double r = rhs[3 * i + c] - static_cast<double>(degree_[i]) * x[3 * i + c];
      for (auto k = rowBegin_[i]; k < rowBegin_[i + 1]; ++k) {
        r += x[3 * static_cast<std::size_t>(neighbours_[k]) + c];
      }
      residualSquared += r * r;
      rhsSquared += static_cast<double>(rhs[3 * i + c]) * rhs[3 * i + c];
    }
  }
  return std::sqrt(rhsSquared > 0 ? residualSquared / rhsSquared : residualSquared);
}

void checkChannelSpans(std::size_t unknowns, std::size_t rhsSize, std::size_t xSize) {
  if (rhsSize != 3 * unknowns || xSize != 3 * unknowns) {
    throw std::invalid_argument(fmt::format(
        "Poisson solve: {} right-hand side and {} solution values for {} unknowns (3 each)",
        rhsSize, xSize, unknowns));
  }
}

}  // namespace surroundd::processing
