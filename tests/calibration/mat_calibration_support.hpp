#pragma once
// Shared by the mat calibration tests: a rig preset's cameras looking at a generated calibration
// mat, each picture rendered from the true pose, with the rig's mount a few centimetres and
// degrees off as the nominal one.

#include <string>
#include <vector>

#include "processing/calibration/mat_calibration.hpp"
#include "tests/calibration/calibration_test_support.hpp"
#include "tools/synth/calibration_mat.hpp"

namespace surroundd::calibration::testing {

struct MatScene {
  std::vector<processing::CameraCalibration> truth;
  processing::MatLayout mat;
  std::vector<cv::Mat> pictures;  // 8-bit BGR, per camera
};

// `drawn`: the boards that are really on the ground (default: the whole mat).
inline std::vector<cv::Mat> matPictures(const std::vector<processing::CameraCalibration>& cameras,
                                        const processing::MatLayout& drawn) {
  std::vector<cv::Mat> pictures;
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    pictures.push_back(groundView(cameras[c], synth::printsOf(drawn), 100 + c));
  }
  return pictures;
}

inline MatScene matScene(const std::string& preset, const synth::GroundMatRequest& request) {
  MatScene scene;
  scene.truth = presetCameras(preset, kGroundViewSize);
  scene.mat = synth::groundMatAroundRig(scene.truth, request);
  scene.pictures = matPictures(scene.truth, scene.mat);
  return scene;
}

inline std::vector<processing::MatView> nominalViews(const MatScene& scene,
                                                     const std::vector<cv::Mat>& pictures) {
  std::vector<processing::MatView> views;
  for (std::size_t c = 0; c < scene.truth.size(); ++c) {
    processing::MatView view{scene.truth[c], toGray(pictures[c])};
    view.nominal.pose = nominal(scene.truth[c].pose);
    views.push_back(std::move(view));
  }
  return views;
}

}  // namespace surroundd::calibration::testing
