#include "render/guideline_layer.hpp"

#include <cmath>

#include <opencv2/imgproc.hpp>

namespace surroundd::render {

GuidelineLayer::GuidelineLayer(SurroundScene& scene, const processing::VehicleDimensions& car,
                               GuidelineSettings settings)
    : scene_(scene), car_(car), settings_(std::move(settings)) {
  const std::size_t most = maxGuidelineVertices(settings_);
  vertices_.reserve(most);
  scene_.reserveGuidelines(most);
}

void GuidelineLayer::show(std::optional<GuidelinePose> pose) {
  std::optional<std::pair<Travel, long>> shown;
  if (pose) shown = std::pair{pose->travel, std::lround(pose->steeringDeg * 10)};
  if (shown == shown_) return;
  shown_ = shown;
  vertices_.clear();
  if (shown) {
    guidelines(car_, settings_, shown->first, static_cast<double>(shown->second) / 10, vertices_);
  }
  scene_.setGuidelines(vertices_);
  ++version_;
}

void GuidelineOverlay::layOver(SurroundView& view, const GuidelineLayer& layer, cv::Mat& picture) {
  if (version_ != layer.version()) {
    view.guidelineLayer(0).copyTo(guides_);
    cv::cvtColor(guides_, grey_, cv::COLOR_BGR2GRAY);
    cv::threshold(grey_, mask_, 0, 255, cv::THRESH_BINARY);
    version_ = layer.version();
  }
  guides_.copyTo(picture, mask_);
}

}  // namespace surroundd::render
