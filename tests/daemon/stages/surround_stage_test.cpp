// The surround stage on its own, given hand-built FrameWorks of synth_seams' first frames after
// the panorama stage, with one output of the top view: a view gathered through its own table
// (render.view_lut) needs no panorama and goes out in its own set; one drawn by OpenGL needs the
// panorama and goes out with the next set (or at the run's end); both show the same picture, and
// the reversing guidelines are laid over the gathered one where OpenGL draws them.

#include "daemon/stages/surround_stage.hpp"

#include <array>
#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "common/work_pool.hpp"
#include "daemon/stages/panorama_stage.hpp"
#include "daemon/stages/surround_renderer.hpp"
#include "tests/daemon/stages/seams_frame_set.hpp"
#include "tests/support/test_support.hpp"

namespace surroundd::daemon {
namespace {

const cv::Size kViewSize{320, 240};

Config topViewConfig(const testing::TempDir& dir, bool viewLut) {
  return testing::seamsConfig(dir, "0",
                              std::string(R"(rig: {file: rig.yaml}
panorama: {width_px: 1024, height_px: 512, cache_dir: lut-cache}
render: {view: top, width_px: 320, height_px: 240, view_lut: )") +
                                  (viewLut ? "true" : "false") + R"(}
outputs:
  - {type: video, stream: surround, path: top.mp4}
)");
}

// The panorama and surround stages of one config, with its one output, as the pipeline has them.
class Stages {
 public:
  Stages(const Config& config, WorkPool& pool)
      : panorama_(std::make_unique<PanoramaStage>(config, pool)) {
    auto& panorama = static_cast<PanoramaStage&>(*panorama_);
    auto surround = std::make_unique<SurroundStage>(
        config, std::move(*openSurroundRenderer(config).get()), panorama, PixelFormat::kBgr);
    surround_ = surround.get();
    stages_.push_back(std::move(surround));
    outputs_.addPicture(config.outputs.at(0), kViewSize, nullptr,
                        surround_->makeView(kViewSize, ViewKind::kTop));
    outputs_.setRenderer(&surround_->context());
    surround_->prepare(outputs_, true);
  }
  ~Stages() {
    std::vector<std::string> written;
    outputs_.finish(
        streamTime_, [](auto&) { return cv::Mat(); }, written);
  }
  Stages(const Stages&) = delete;
  Stages& operator=(const Stages&) = delete;

  // One set through both stages; whether the surround stage asked for the panorama.
  bool process(const capture::FrameSet& set) {
    FrameWork work{.set = set, .bgrBuffers = bgrBuffers_, .outputs = outputs_};
    work.streamTime = streamTime_;
    work.later = stages_;
    const bool needed = work.needed(Need::kPanorama);
    times_.beginSet();
    panorama_->process(work, times_);
    EXPECT_EQ(work.panorama != nullptr, needed);
    surround_->process(work, times_);
    times_.endSet();
    streamTime_ += std::chrono::milliseconds(33);
    return needed;
  }
  // The picture handed to the output last; empty before the first.
  cv::Mat handedOver() {
    return outputs_.latestPicture([](auto&) { return cv::Mat(); }).clone();
  }
  SurroundStage& surround() { return *surround_; }
  PipelineOutputs& outputs() { return outputs_; }

 private:
  std::unique_ptr<PipelineStage> panorama_;
  std::vector<std::unique_ptr<PipelineStage>> stages_;  // the surround stage, after the panorama
  SurroundStage* surround_;
  PipelineOutputs outputs_{30, false};
  std::array<cv::Mat, kMaxCameras> bgrBuffers_;
  StageTimes times_;
  std::chrono::nanoseconds streamTime_{0};
};

class SurroundStageTest : public ::testing::Test {
 protected:
  const testing::TempDir dir_;
  WorkPool pool_{1};
  const testing::SeamsFirstFrames frames_;
};

TEST_F(SurroundStageTest, AGatheredViewNeedsNoPanoramaAndGoesOutInItsOwnSet) {
  Stages stages(topViewConfig(dir_, true), pool_);
  EXPECT_FALSE(stages.process(frames_.set)) << "the panorama was asked for";
  const cv::Mat picture = stages.handedOver();
  ASSERT_EQ(picture.size(), kViewSize) << "no picture in the set it was gathered in";
  EXPECT_GT(cv::mean(picture)[1], 20.0) << "the ground is lit";
}

TEST_F(SurroundStageTest, ADrawnViewNeedsThePanoramaAndGoesOutWithTheNextSet) {
  Stages drawn(topViewConfig(dir_, false), pool_);
  EXPECT_TRUE(drawn.process(frames_.set));
  EXPECT_TRUE(drawn.handedOver().empty()) << "handed over before its read-back";
  EXPECT_TRUE(drawn.process(frames_.set));
  const cv::Mat picture = drawn.handedOver();
  ASSERT_EQ(picture.size(), kViewSize);

  // The same view gathered through its table: within the samplings' differences.
  Stages gathered(topViewConfig(dir_, true), pool_);
  gathered.process(frames_.set);
  cv::Mat difference;
  cv::absdiff(picture, gathered.handedOver(), difference);
  EXPECT_LT(cv::mean(difference)[1], 4.0);
}

// Reversing: the gathered view gets the guidelines as OpenGL draws them on the drawn one; in
// drive (render.guidelines: reverse) they are gone again.
TEST_F(SurroundStageTest, TheGuidelinesAreLaidOverAGatheredViewAsTheyAreDrawn) {
  Stages gathered(topViewConfig(dir_, true), pool_);
  gathered.process(frames_.set);
  const cv::Mat plain = gathered.handedOver();
  vehicle::VehicleSignals reversing;
  reversing.gear = vehicle::Gear::kReverse;
  reversing.steeringDeg = 200;
  gathered.surround().setVehicleSignals(reversing);
  gathered.process(frames_.set);
  const cv::Mat guided = gathered.handedOver();

  Stages drawn(topViewConfig(dir_, false), pool_);
  drawn.surround().setVehicleSignals(reversing);
  drawn.process(frames_.set);
  drawn.process(frames_.set);
  const cv::Mat drawnGuided = drawn.handedOver();

  cv::Mat changed;
  cv::compare(plain, guided, changed, cv::CMP_NE);
  cv::Mat lines;
  cv::reduce(changed.reshape(1, static_cast<int>(changed.total())), lines, 1, cv::REDUCE_MAX);
  lines = lines.reshape(1, plain.rows);
  ASSERT_GT(cv::countNonZero(lines), 100) << "no guidelines laid";
  EXPECT_LT(cv::norm(guided, drawnGuided, cv::NORM_L1, lines) / cv::countNonZero(lines), 3 * 8.0)
      << "laid where OpenGL does not draw them";

  vehicle::VehicleSignals driving;
  driving.gear = vehicle::Gear::kDrive;
  gathered.surround().setVehicleSignals(driving);
  gathered.process(frames_.set);
  EXPECT_EQ(cv::norm(gathered.handedOver(), plain, cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace surroundd::daemon
