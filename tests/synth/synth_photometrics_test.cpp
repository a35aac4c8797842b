// The photometric parameters in ground_truth.yaml are in their documented ranges and really
// describe the videos: the noise-free image put through the written model predicts each decoded
// frame to within the sensor noise and the codec's error, and a model with a wrong gain does not.

#include <gtest/gtest.h>

#include "daemon/config/rig_yaml.hpp"
#include "tests/synth/synth_test_support.hpp"
#include "tools/synth/photometrics.hpp"
#include "tools/synth/scene_renderer.hpp"

namespace surroundd::synth {
namespace {

CameraPhotometrics fromYaml(const YAML::Node& p) {
  CameraPhotometrics out;
  out.gain = p["gain"].as<double>();
  const auto wb = p["white_balance_bgr"].as<std::vector<double>>();
  out.whiteBalance = {wb.at(0), wb.at(1), wb.at(2)};
  out.gamma = p["gamma"].as<double>();
  out.vignetting = p["vignetting"].as<double>();
  out.noiseSigma = p["noise_sigma"].as<double>();
  out.driftAmplitude = p["drift_amplitude"].as<double>();
  out.driftPeriodS = p["drift_period_s"].as<double>();
  out.driftPhaseRad = p["drift_phase_rad"].as<double>();
  return out;
}

// The noise-free image through the model (without noise), as the generator applies it.
cv::Mat predict(const CameraPhotometrics& model, const CameraRays& rays, const cv::Mat& truth,
                int frame, double seconds) {
  CameraPhotometrics noiseless = model;
  noiseless.noiseSigma = 0;
  const PhotometricCamera camera(noiseless, 0, 0, rays.offAxisAngle(), rays.fisheye());
  const auto state = camera.frame(frame, seconds);
  cv::Mat radiance;
  truth.convertTo(radiance, CV_32FC3);
  cv::Mat out(truth.size(), CV_8UC3);
  for (int y = 0; y < truth.rows; ++y) {
    camera.convertRow(state, radiance.ptr<cv::Vec3f>(y), out.ptr<cv::Vec3b>(y), y, 0, truth.cols);
  }
  return out;
}

double meanAbs(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  const cv::Scalar m = cv::mean(diff);
  return (m[0] + m[1] + m[2]) / 3;
}

// --photometrics extreme: the random cameras, with gain and white balance pushed to opposite
// ends of their ranges for colour sources and targets.
TEST(SynthPhotometrics, ExtremeSetsSourcesAndTargetsAtOppositeEnds) {
  for (const bool source : {true, false}) {
    const CameraPhotometrics random = randomPhotometrics(7, 2, 1.5, true);
    const CameraPhotometrics extreme = extremePhotometrics(7, 2, 1.5, true, source);
    EXPECT_DOUBLE_EQ(extreme.gain, source ? 0.7 : 1.3);
    EXPECT_EQ(extreme.whiteBalance,
              source ? cv::Vec3d(0.85, 1.0, 1.15) : cv::Vec3d(1.15, 1.0, 0.85));
    CameraPhotometrics rest = extreme;
    rest.gain = random.gain;
    rest.whiteBalance = random.whiteBalance;
    EXPECT_EQ(rest, random);  // gamma, vignetting, noise and drift as drawn
  }
}

TEST(SynthPhotometrics, ParametersAreInRangeAndDescribeTheVideos) {
  const auto folder = testing::fixture("synth_small");
  const YAML::Node truth = YAML::LoadFile((folder / "ground_truth.yaml").string());
  const auto rig = daemon::loadRigFile(folder / "rig.yaml");
  ASSERT_EQ(rig.size(), truth["cameras"].size());
  std::set<double> gains;
  for (std::size_t c = 0; c < rig.size(); ++c) {
    const YAML::Node camera = truth["cameras"][c];
    const CameraPhotometrics p = fromYaml(camera["photometrics"]);
    EXPECT_GE(p.gain, 0.7);
    EXPECT_LE(p.gain, 1.3);
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE(p.whiteBalance[k], 0.85);
      EXPECT_LE(p.whiteBalance[k], 1.15);
    }
    EXPECT_GE(p.gamma, 0.9);
    EXPECT_LE(p.gamma, 1.1);
    EXPECT_GT(p.vignetting, 0.0);
    EXPECT_LE(p.vignetting, 0.4);
    EXPECT_EQ(p.noiseSigma, 1.5);
    EXPECT_GT(p.driftAmplitude, 0.0);
    EXPECT_LE(p.driftAmplitude, 0.1);
    EXPECT_GE(p.driftPeriodS, 6.0);
    EXPECT_LE(p.driftPeriodS, 12.0);
    gains.insert(p.gain);

    const auto& name = rig[c].calibration.name;
    const CameraRays rays(rig[c].calibration);
    const auto video = testing::decodeAll(folder / camera["video"].as<std::string>()).images;
    for (const auto& entry : truth["ground_truth_frames"]) {
      const int k = entry["frame"].as<int>();
      const cv::Mat clean =
          cv::imread((folder / entry["cameras"][name]["image"].as<std::string>()).string());
      const double t = entry["time_s"].as<double>();
      const cv::Mat& frame = video.at(static_cast<std::size_t>(k));
      const double error = meanAbs(predict(p, rays, clean, k, t), frame);
      CameraPhotometrics wrong = p;
      wrong.gain *= 1.1;
      const double wrongError = meanAbs(predict(wrong, rays, clean, k, t), frame);
      // Noise of sigma 1.5 alone gives a mean absolute difference of 1.2.
      EXPECT_LE(error, 2.5) << name << " frame " << k;
      EXPECT_GT(wrongError, error + 3) << name << " frame " << k;
    }
  }
  EXPECT_EQ(gains.size(), rig.size()) << "each camera draws its own parameters";
}

}  // namespace
}  // namespace surroundd::synth
