// The batched DCT of the rectangle Poisson solver against the definition, for lengths made of
// every kind of FFT stage (4, 2, 3, 5, a larger prime, and 1).

#include "processing/column_dct.hpp"

#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace surroundd::processing {
namespace {

class ColumnDctLengths : public ::testing::TestWithParam<int> {};

TEST_P(ColumnDctLengths, MatchesTheDefinitionAndInverts) {
  const int length = GetParam();
  const int width = 24;
  std::mt19937 random(static_cast<unsigned>(length));
  std::uniform_real_distribution<float> value(-60.0f, 60.0f);
  std::vector<float> signal(static_cast<std::size_t>(length) * width);
  for (float& v : signal) v = value(random);

  std::vector<float> data = signal;
  ColumnDct dct(length, width);
  dct.forward(data.data());
  double largestError = 0;
  for (int k = 0; k < length; ++k) {
    for (int column = 0; column < width; ++column) {
      double sum = 0;
      for (int n = 0; n < length; ++n) {
        sum += signal[static_cast<std::size_t>(n) * width + column] *
               std::cos(std::numbers::pi * k * (n + 0.5) / length);
      }
      const double orthonormal = sum * std::sqrt((k == 0 ? 1.0 : 2.0) / length);
      largestError = std::max(
          largestError, std::abs(orthonormal - data[static_cast<std::size_t>(k) * width + column]));
    }
  }
  EXPECT_LT(largestError, 1e-4) << "forward, length " << length;

  dct.inverse(data.data());
  double largestRoundTrip = 0;
  for (std::size_t i = 0; i < data.size(); ++i) {
    largestRoundTrip =
        std::max(largestRoundTrip, static_cast<double>(std::abs(data[i] - signal[i])));
  }
  EXPECT_LT(largestRoundTrip, 1e-4) << "round trip, length " << length;
}

INSTANTIATE_TEST_SUITE_P(ColumnDct, ColumnDctLengths,
                         ::testing::Values(1, 2, 3, 4, 5, 6, 7, 8, 12, 15, 45, 64, 97, 180, 256,
                                           262));

TEST(ColumnDct, RejectsWidthsThatDoNotPairUp) {
  EXPECT_THROW(ColumnDct(16, 12), std::invalid_argument);
  EXPECT_THROW(ColumnDct(0, 8), std::invalid_argument);
}

}  // namespace
}  // namespace surroundd::processing
