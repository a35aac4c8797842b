#include "processing/lens/camera_model.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace surroundd::processing {
namespace {

// The alternative of Lens that `intrinsics.model` names.
template <std::size_t I = 0>
Lens lensOf(const Intrinsics& intrinsics) {
  if constexpr (I < std::variant_size_v<Lens>) {
    if (static_cast<std::size_t>(intrinsics.model) == I) {
      return Lens(std::in_place_index<I>, intrinsics);
    }
    return lensOf<I + 1>(intrinsics);
  } else {
    throw std::invalid_argument(
        fmt::format("no lens model {}", static_cast<int>(intrinsics.model)));
  }
}

}  // namespace

CameraModel::CameraModel(const Intrinsics& intrinsics)
    : intrinsics_(intrinsics), lens_(lensOf(intrinsics)) {
  const LensField field = std::visit([](const auto& lens) { return lens.field(); }, lens_);
  if (isWideAngle(intrinsics_.model)) intrinsics_.maxFieldAngleRad = field.fieldRad;
  if (field.fieldRad < field.askedRad) {
    const cv::Size size = intrinsics_.imageSize;
    bool inImage = false;
    for (const cv::Point2d corner :
         {cv::Point2d(-0.5, -0.5), cv::Point2d(size.width - 0.5, -0.5),
          cv::Point2d(-0.5, size.height - 0.5), cv::Point2d(size.width - 0.5, size.height - 0.5)}) {
      const cv::Point2d sensor =
          std::visit([&](const auto& lens) { return lens.sensorPoint(corner); }, lens_);
      inImage = inImage || std::hypot(sensor.x, sensor.y) > field.edgeRadius;
    }
    fieldCut_ = FieldCut{field.fieldRad, field.askedRad, inImage};
  }
}

bool CameraModel::inImage(const cv::Point2d& pixel) const {
  // Pixel centres are at integer coordinates, so the image covers [-0.5, size - 0.5).
  return pixel.x >= -0.5 && pixel.y >= -0.5 && pixel.x < intrinsics_.imageSize.width - 0.5 &&
         pixel.y < intrinsics_.imageSize.height - 0.5;
}

std::string lensKey(const Intrinsics& intrinsics) {
  // As many names as Intrinsics (and its Ocam) has members: one more there is an error here.
  const auto& [model, imageSize, fx, fy, cx, cy, distortion, maxFieldAngleRad, ocam] = intrinsics;
  const auto& [c, d, e, worldToImage, imageToWorld] = ocam;
  return fmt::format(
      "{} {}x{} f {:a} {:a} c {:a} {:a} d {:a} fov {:a} ocam {:a} {:a} {:a} world to image {:a} "
      "image to world {:a}",
      lensModelName(model), imageSize.width, imageSize.height, fx, fy, cx, cy,
      fmt::join(distortion, " "), maxFieldAngleRad, c, d, e, fmt::join(worldToImage, " "),
      fmt::join(imageToWorld, " "));
}

}  // namespace surroundd::processing
