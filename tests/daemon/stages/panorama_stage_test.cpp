// The panorama stage on its own, given hand-built FrameWorks of synth_seams' first frames: it
// stitches the panorama only for a set that a later stage says it needs, hands it on in the
// FrameWork, and asks after the stages before it have had the set (a camera they found faulty is
// marked in that set's panorama). Which stages need the panorama: an output of it (the stream
// output stage), whether or not it wants this set.

#include "daemon/stages/panorama_stage.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "common/work_pool.hpp"
#include "daemon/stages/stream_output_stage.hpp"
#include "tests/daemon/stages/seams_frame_set.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::daemon {
namespace {

// `extra`: sections of the config's own.
Config panoramaConfig(const testing::TempDir& dir, const std::string& stream,
                      const std::string& extra = "") {
  return testing::seamsConfig(dir, "0", R"(rig: {file: rig.yaml}
panorama: {width_px: 1024, height_px: 512, cache_dir: lut-cache}
)" + extra + R"(outputs:
  - {type: snapshot, stream: )" + stream + R"(, path: picture.png}
)");
}

// A later stage that needs the panorama or not, and remembers what it was asked with.
class LaterStage final : public PipelineStage {
 public:
  explicit LaterStage(bool needsPanorama) : needsPanorama_(needsPanorama) {}
  void process(FrameWork& /*work*/, StageTimes& /*times*/) override {}
  bool needs(Need what, const FrameWork& work) const override {
    askedWithFault_ = work.faults[1] != nullptr;
    return what == Need::kPanorama && needsPanorama_;
  }
  bool askedWithFault() const { return askedWithFault_; }

 private:
  bool needsPanorama_;
  mutable bool askedWithFault_ = false;  // a test's record of what it was asked with
};

// What one set through the stage gave: its FrameWork::panorama, and whether the later stage was
// asked knowing camera 1 faulty.
struct Processed {
  const cv::Mat* panorama;
  bool askedWithFault;
};

class PanoramaStageTest : public ::testing::Test {
 protected:
  // The stage given the first frames, with camera 1 faulty or not, before a stage that needs
  // the panorama or not.
  Processed process(PanoramaStage& stage, bool needed, bool faulty) {
    std::vector<std::unique_ptr<PipelineStage>> stages;
    stages.push_back(std::make_unique<LaterStage>(needed));
    FrameWork work{.set = frames_.set, .bgrBuffers = bgrBuffers_, .outputs = outputs_};
    if (faulty) work.faults[1] = "frozen";
    work.later = stages;
    times_.beginSet();
    stage.process(work, times_);
    times_.endSet();
    return {work.panorama, static_cast<const LaterStage&>(*stages.front()).askedWithFault()};
  }

  const testing::TempDir dir_;
  const Config config_ = panoramaConfig(dir_, "panorama");
  WorkPool pool_{1};
  const testing::SeamsFirstFrames frames_;
  std::array<cv::Mat, kMaxCameras> bgrBuffers_;
  PipelineOutputs outputs_{30, false};
  StageTimes times_;
};

TEST_F(PanoramaStageTest, StitchesThePanoramaOnlyForASetALaterStageNeedsIt) {
  PanoramaStage stage(config_, pool_);
  const auto lit = [](const cv::Mat& picture) {
    cv::Mat green;
    cv::extractChannel(picture, green, 1);
    return cv::countNonZero(green) / static_cast<double>(green.total());
  };
  EXPECT_EQ(process(stage, false, false).panorama, nullptr);
  EXPECT_EQ(lit(stage.picture()), 0.0) << "stitched for a set nothing needed it for";

  const cv::Mat* panorama = process(stage, true, false).panorama;
  ASSERT_EQ(panorama, &stage.picture());
  ASSERT_EQ(panorama->size(), stage.lut().size);
  // The generated ground and walls around the car: most of the panorama is lit.
  EXPECT_GT(lit(*panorama), 0.5);
}

TEST_F(PanoramaStageTest, AsksTheLaterStagesAfterTheEarlierOnesFoundAFaultyCamera) {
  PanoramaStage stage(config_, pool_);
  const Processed whole = process(stage, true, false);
  EXPECT_FALSE(whole.askedWithFault);
  ASSERT_NE(whole.panorama, nullptr);
  const cv::Mat before = whole.panorama->clone();
  const Processed marked = process(stage, true, true);
  EXPECT_TRUE(marked.askedWithFault);
  ASSERT_NE(marked.panorama, nullptr);
  // Camera 1's part of the panorama is marked; the rest is as it was.
  cv::Mat changed;
  cv::compare(before, *marked.panorama, changed, cv::CMP_NE);
  changed = changed.reshape(1, 0);
  const double share = cv::countNonZero(changed) / static_cast<double>(changed.total());
  EXPECT_GT(share, 0.05);
  EXPECT_LT(share, 0.6);
}

// With colour_correction.balance the cameras' gains go before the field, in the panorama and in
// a view gathered through a LUT of its own alike: a view that samples the panorama pixel for
// pixel is the panorama, within the field's bilinear sampling (the panorama's is bicubic).
TEST_F(PanoramaStageTest, AViewIsBalancedAsThePanoramaIs) {
  const Config balanced = panoramaConfig(dir_, "panorama", "colour_correction: {balance: true}\n");
  PanoramaStage plain(config_, pool_);
  PanoramaStage stage(balanced, pool_);
  ASSERT_NE(process(plain, true, false).panorama, nullptr);
  ASSERT_NE(process(stage, true, false).panorama, nullptr);
  const auto meanDifference = [](const cv::Mat& a, const cv::Mat& b) {
    cv::Mat difference;
    cv::absdiff(a, b, difference);
    const cv::Scalar mean = cv::mean(difference);
    return (mean[0] + mean[1] + mean[2]) / 3;
  };
  // The balance changes the picture: agreeing below is not agreeing on nothing.
  EXPECT_GT(meanDifference(plain.picture(), stage.picture()), 3.0);

  const cv::Size size = stage.lut().size;
  cv::Mat positions(size, CV_32FC2);
  for (int v = 0; v < size.height; ++v) {
    for (int u = 0; u < size.width; ++u) {
      positions.at<cv::Vec2f>(v, u) = {static_cast<float>(u), static_cast<float>(v)};
    }
  }
  const auto view = stage.buildView(positions).get();
  cv::Mat picture(size, CV_8UC3);
  FrameWork work{.set = frames_.set, .bgrBuffers = bgrBuffers_, .outputs = outputs_};
  stage.gather(*view, picture);
  stage.correct(*view, work, picture, nullptr);
  EXPECT_LT(meanDifference(picture, stage.picture()), 0.5);
}

// What the report shows of the correction: every seam by its cameras' names, with its steps, and
// the balance's gains per camera.
TEST_F(PanoramaStageTest, ReportsEachSeamOfTheCorrectionAndTheBalancesGains) {
  const Config balanced = panoramaConfig(dir_, "panorama", "colour_correction: {balance: true}\n");
  PanoramaStage stage(balanced, pool_);
  PipelineReport before;
  stage.report(before);
  ASSERT_TRUE(before.colour.has_value());
  ASSERT_NE(process(stage, true, false).panorama, nullptr);
  PipelineReport report;
  stage.report(report);
  ASSERT_TRUE(report.colour.has_value());
  EXPECT_TRUE(report.colour->balanced);
  ASSERT_GE(report.colour->seams.size(), testing::kSeamsCameras.size());  // at least a ring
  for (const auto& seam : report.colour->seams) {
    const auto slash = seam.name.find('/');
    ASSERT_NE(slash, std::string::npos) << seam.name;
    for (const std::string& camera : {seam.name.substr(0, slash), seam.name.substr(slash + 1)}) {
      EXPECT_NE(std::ranges::find(testing::kSeamsCameras, camera), testing::kSeamsCameras.end())
          << seam.name;
    }
    EXPECT_GT(seam.blocks, 0) << seam.name;
    EXPECT_LE(seam.stepCorrected, seam.stepUncorrected + 0.5) << seam.name;
  }
  EXPECT_TRUE(std::ranges::any_of(report.colour->seams, [](const auto& seam) {
    return seam.stepCorrected < seam.stepUncorrected / 2;
  })) << "no seam was corrected";
  ASSERT_EQ(report.colour->balanceGains.size(), testing::kSeamsCameras.size());
  EXPECT_TRUE(std::ranges::any_of(report.colour->balanceGains, [](const auto& gains) {
    return std::abs(gains[1] - 1.0F) > 0.02F;
  })) << "the generated cameras' exposures differ";
}

TEST(StreamOutputStage, NeedsThePanoramaWhereAnOutputShowsIt) {
  const testing::TempDir dir;
  const cv::Mat picture(512, 1024, CV_8UC3, cv::Scalar::all(0));
  const capture::FrameSet set;
  std::array<cv::Mat, kMaxCameras> bgrBuffers;
  for (const std::string stream : {"panorama", "mosaic"}) {
    const Config config = panoramaConfig(dir, stream);
    PipelineOutputs outputs(30, false);
    outputs.addPicture(config.outputs.at(0), picture.size(), &picture, nullptr);
    const FrameWork work{.set = set, .bgrBuffers = bgrBuffers, .outputs = outputs};
    EXPECT_EQ(StreamOutputStage().needs(Need::kPanorama, work), stream == "panorama") << stream;
  }
}

}  // namespace
}  // namespace surroundd::daemon
