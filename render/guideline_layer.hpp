#pragma once
// The parking guidelines as a layer of the surround views (guidelines.hpp makes their triangles):
// what they show now, handed to the scene every view draws (GuidelineLayer), and laid over a
// picture of a view that the CPU made rather than OpenGL drew (GuidelineOverlay). The steering is
// taken to a tenth of a degree: a finer change is not worth drawing them again, which for a
// picture laid over on the CPU means reading them back from OpenGL.
//
// Threads: the scene's context's.

#include <optional>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "render/car_model.hpp"
#include "render/guidelines.hpp"
#include "render/surround_scene.hpp"
#include "render/surround_view.hpp"

namespace surroundd::render {

// What the guidelines show: the way the vehicle goes, at its steering-wheel angle.
struct GuidelinePose {
  Travel travel = Travel::kReverse;
  double steeringDeg = 0;
};

class GuidelineLayer {
 public:
  // Reserves `scene`'s buffer for the most vertices `settings` make: showing allocates nothing.
  // `scene` must outlive the layer.
  GuidelineLayer(SurroundScene& scene, const processing::VehicleDimensions& car,
                 GuidelineSettings settings);

  // The guidelines for `pose` in every view of the scene from now on; none hides them.
  void show(std::optional<GuidelinePose> pose);
  bool shown() const { return shown_.has_value(); }
  // Changes each time what the views show changes.
  int version() const { return version_; }

 private:
  SurroundScene& scene_;
  processing::VehicleDimensions car_;
  GuidelineSettings settings_;
  std::vector<GuidelineVertex> vertices_;         // reserved at start: filled in place
  std::optional<std::pair<Travel, long>> shown_;  // the steering in tenths of a degree
  int version_ = 0;
};

// A view's guidelines, over a picture of that view made on the CPU: read back from OpenGL once per
// change of what they show (GuidelineLayer::version()), and laid over every picture meanwhile.
class GuidelineOverlay {
 public:
  // `picture`: 8-bit BGR, of `view`'s size.
  void layOver(SurroundView& view, const GuidelineLayer& layer, cv::Mat& picture);

 private:
  cv::Mat guides_;  // as the view shows them, on black
  cv::Mat grey_;
  cv::Mat mask_;  // CV_8U: where they are
  int version_ = -1;
};

}  // namespace surroundd::render
