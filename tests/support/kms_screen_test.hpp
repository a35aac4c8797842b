#pragma once
// The base of the tests that take over a KMS screen: the one scripts/device-vm.sh's machine gives
// them (SURROUNDD_KMS_SCREEN), or skipped; and a look at what it shows (kms_scanout.hpp).

#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "tests/support/kms_scanout.hpp"

namespace surroundd::testing {

class KmsScreenTest : public ::testing::Test {
 protected:
  void SetUp() override {
    card_ = kmsScreenForTests();
    if (card_.empty()) {
      GTEST_SKIP() << "no KMS screen to take over here (ctest runs these on a virtual machine's: "
                      "the tests labelled device_vm)";
    }
  }

  // The screen shows `expected` in `area` of its mode (within `maxLevels`), and black around it.
  void expectShown(const cv::Mat& expected, const cv::Rect& area, double maxLevels) const {
    const auto shown = scanout(card_);
    ASSERT_FALSE(shown.picture.empty()) << "the screen shows nothing";
    const auto against = compareShown(shown.picture, expected, area);
    EXPECT_LE(against.largestDifference, maxLevels);
    EXPECT_EQ(against.litAround, 0) << "the bars around it are not black";
  }

  std::filesystem::path card_;
};

}  // namespace surroundd::testing
