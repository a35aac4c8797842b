// The colour balance's fit on its own: four cameras in a ring, each seeing the ground with a
// factor of its own per channel (exposure and white balance); the pairs' ratios are what the seam
// blocks would measure. The gains undo the factors up to one common factor per channel, which
// keeps the cameras' average (log mean 0); a missing camera keeps its gains; noise is smoothed
// over sets; a gain past the bounds is clamped and said once.

#include "processing/colour/colour_balance.hpp"

#include <array>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace surroundd::processing {
namespace {

const std::vector<std::string> kNames{"front", "right", "back", "left"};
// Per camera, what it does to the ground's B G R: up to +-30 % per channel, one camera a stop
// darker.
const std::array<cv::Vec3f, 4> kFactors{cv::Vec3f(1.3f, 1.0f, 0.8f), cv::Vec3f(0.9f, 1.1f, 1.25f),
                                        cv::Vec3f(0.5f, 0.55f, 0.45f),
                                        cv::Vec3f(1.0f, 0.75f, 1.2f)};

// Each neighbouring pair of the ring: log(b's level / a's) of the same ground.
std::vector<CameraPairRatio> ringPairs(const std::array<cv::Vec3f, 4>& factors,
                                       double weight = 40) {
  std::vector<CameraPairRatio> pairs;
  for (std::uint8_t a = 0; a < 4; ++a) {
    const auto b = static_cast<std::uint8_t>((a + 1) % 4);
    cv::Vec3f ratio;
    for (int c = 0; c < 3; ++c) ratio[c] = std::log(factors[b][c] / factors[a][c]);
    pairs.push_back({a, b, ratio, weight});
  }
  return pairs;
}

const std::array<std::uint8_t, 4> kAll{1, 1, 1, 1};

TEST(ColourBalance, UndoesEachCamerasFactorsAndKeepsTheirAverage) {
  ColourBalance balance(kNames, 0.25, 4.0, 0.0);
  for (const auto& gain : balance.gains()) EXPECT_EQ(gain, cv::Vec3f(1, 1, 1));
  balance.update(ringPairs(kFactors), kAll);
  for (int c = 0; c < 3; ++c) {
    double logMean = 0;
    for (std::size_t k = 0; k < 4; ++k) logMean += std::log(balance.gains()[k][c]) / 4;
    EXPECT_NEAR(logMean, 0, 1e-3) << "channel " << c;
    // Every camera's ground comes out alike: g_k f_k is one value per channel.
    const double common = balance.gains()[0][c] * kFactors[0][c];
    for (std::size_t k = 1; k < 4; ++k) {
      EXPECT_NEAR(balance.gains()[k][c] * kFactors[k][c], common, 1e-3 * common)
          << "camera " << k << ", channel " << c;
    }
  }
  EXPECT_TRUE(balance.notesOfLastUpdate().empty());
}

// A reference camera the user names (colour_correction.balance_reference): its gains stay 1 and
// every other camera takes its colour; a set without it cannot say where the others go, so none
// changes.
TEST(ColourBalance, WithAReferenceEveryCameraTakesThatCamerasColour) {
  ColourBalance balance(kNames, 0.25, 4.0, 0.0, "back");
  balance.update(ringPairs(kFactors), kAll);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(balance.gains()[2][c], 1.0, 1e-3) << "channel " << c;
    for (std::size_t k = 0; k < 4; ++k) {
      EXPECT_NEAR(balance.gains()[k][c] * kFactors[k][c], kFactors[2][c], 1e-3)
          << "camera " << k << ", channel " << c;
    }
  }
  const std::vector<cv::Vec3f> fitted = balance.gains();
  std::array<cv::Vec3f, 4> changed = kFactors;
  changed[0] *= 1.2F;
  const std::array<std::uint8_t, 4> withoutBack{1, 1, 0, 1};
  balance.update(ringPairs(changed), withoutBack);
  EXPECT_EQ(balance.gains(), fitted);

  EXPECT_THROW(ColourBalance(kNames, 0.25, 4.0, 0.0, "roof"), std::invalid_argument);
}

TEST(ColourBalance, AMissingCameraKeepsItsGainsAndTheOthersStillAgree) {
  ColourBalance balance(kNames, 0.25, 4.0, 0.0);
  balance.update(ringPairs(kFactors), kAll);
  const cv::Vec3f backBefore = balance.gains()[2];
  // The back camera's exposure changes while it is missing: its pairs are not measured.
  auto factors = kFactors;
  factors[0] *= 1.5f;
  const std::array<std::uint8_t, 4> noBack{1, 1, 0, 1};
  balance.update(ringPairs(factors), noBack);
  EXPECT_EQ(balance.gains()[2], backBefore);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(balance.gains()[0][c] * factors[0][c], balance.gains()[1][c] * factors[1][c], 1e-3);
    EXPECT_NEAR(balance.gains()[3][c] * factors[3][c], balance.gains()[1][c] * factors[1][c], 1e-3);
  }
}

TEST(ColourBalance, FollowsAnExposureChangeWithinAFewSetsWithoutJumping) {
  ColourBalance balance(kNames, 0.25, 4.0, 0.8);
  balance.update(ringPairs(kFactors), kAll);
  auto factors = kFactors;
  factors[1] *= 0.5f;  // the right camera a stop darker from now on
  ColourBalance settled(kNames, 0.25, 4.0, 0.0);
  settled.update(ringPairs(factors), kAll);
  const float target = settled.gains()[1][1];
  float previous = balance.gains()[1][1];
  int sets = 0;
  while (std::abs(balance.gains()[1][1] / target - 1) > 0.02f && sets < 100) {
    balance.update(ringPairs(factors), kAll);
    const float now = balance.gains()[1][1];
    EXPECT_GT(now, previous);  // towards the new gain, never past it
    EXPECT_LE(now, target * 1.0001f);
    previous = now;
    ++sets;
  }
  // 0.8 of the previous set each set: within 2 % in 15 sets, half a second at 30 FPS.
  EXPECT_GE(sets, 5);
  EXPECT_LE(sets, 20);
}

TEST(ColourBalance, AGainPastTheBoundsIsClampedAndSaidOnce) {
  ColourBalance balance(kNames, 0.5, 2.0, 0.0);
  // The back camera two stops darker than the others: its gain for the average is 4^(3/4) = 2.8,
  // theirs 4^(-1/4) = 0.71.
  std::array<cv::Vec3f, 4> factors;
  factors.fill(cv::Vec3f(1, 1, 1));
  factors[2] = cv::Vec3f(0.25f, 0.25f, 0.25f);
  balance.update(ringPairs(factors), kAll);
  ASSERT_EQ(balance.notesOfLastUpdate().size(), 1u);
  EXPECT_NE(balance.notesOfLastUpdate().front().find("camera 'back'"), std::string::npos);
  EXPECT_NE(balance.notesOfLastUpdate().front().find("clamped"), std::string::npos);
  for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(balance.gains()[2][c], 2.0f);
  balance.update(ringPairs(factors), kAll);
  EXPECT_TRUE(balance.notesOfLastUpdate().empty());
}

}  // namespace
}  // namespace surroundd::processing
