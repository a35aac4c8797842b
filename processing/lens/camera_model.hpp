#pragma once
// Lens models: where a 3D point in the camera frame lands in the image, and back.
//
// Camera frame is OpenCV's: x right, y down, z forward (optical axis). Each model is a class of
// its own in this folder (pinhole_lens, fisheye_lens, ocam_lens), matching OpenCV or OCamCalib
// exactly where they define it; a CameraModel holds the one its Intrinsics name, in a
// std::variant, and every call goes to it through std::visit, so a model that lacks a call does
// not compile.
//
// A new model: its class (kModel, kName, kWideAngle, its constructor from Intrinsics, field(),
// sensorPoint(), project(), unproject(), axisFocalPx()), one alternative in Lens and the
// enumerator in LensModel at the same place, and its parameters in Intrinsics (lensKey() does not
// compile until it keys on them).

#include <array>
#include <optional>
#include <string_view>
#include <utility>
#include <variant>

#include <opencv2/core.hpp>

#include "processing/lens/fisheye_lens.hpp"
#include "processing/lens/intrinsics.hpp"
#include "processing/lens/ocam_lens.hpp"
#include "processing/lens/pinhole_lens.hpp"

namespace surroundd::processing {

// Alternative i is the model LensModel(i).
using Lens = std::variant<PinholeLens, FisheyeLens, OcamLens>;

namespace lens_detail {
template <std::size_t... I>
constexpr auto models(std::index_sequence<I...> /*alternatives*/) {
  return std::array{std::variant_alternative_t<I, Lens>::kModel...};
}
template <std::size_t... I>
constexpr auto names(std::index_sequence<I...> /*alternatives*/) {
  return std::array{std::variant_alternative_t<I, Lens>::kName...};
}
template <std::size_t... I>
constexpr auto wideAngles(std::index_sequence<I...> /*alternatives*/) {
  return std::array{std::variant_alternative_t<I, Lens>::kWideAngle...};
}
inline constexpr auto kAlternatives = std::make_index_sequence<std::variant_size_v<Lens>>();
}  // namespace lens_detail

// Every model, in LensModel's order.
inline constexpr auto kLensModels = lens_detail::models(lens_detail::kAlternatives);
static_assert(
    [] {
      for (std::size_t i = 0; i < kLensModels.size(); ++i) {
        if (kLensModels[i] != static_cast<LensModel>(i)) return false;
      }
      return true;
    }(),
    "alternative i of Lens is the model LensModel(i)");

// The model's name as the rig file and the tools' options spell it (lens.model, --lens).
constexpr std::string_view lensModelName(LensModel model) {
  return lens_detail::names(lens_detail::kAlternatives).at(static_cast<std::size_t>(model));
}

// The model named `name` (lensModelName()'s spelling), or none.
constexpr std::optional<LensModel> lensModelNamed(std::string_view name) {
  for (const LensModel model : kLensModels) {
    if (lensModelName(model) == name) return model;
  }
  return std::nullopt;
}

// Whether the model is a wide-angle lens's: its field may reach past 90 degrees, ends at
// maxFieldAngleRad, and shows as an image circle in the picture. A pinhole lens sees only what is
// in front of it, and its field is its picture's.
constexpr bool isWideAngle(LensModel model) {
  return lens_detail::wideAngles(lens_detail::kAlternatives).at(static_cast<std::size_t>(model));
}

class CameraModel {
 public:
  explicit CameraModel(const Intrinsics& intrinsics);

  // Pixel of a camera-frame point; nullopt when the point is behind the lens or outside its field.
  // The pixel may still lie outside the image; use inImage() for that.
  std::optional<cv::Point2d> project(const cv::Vec3d& pointCamera) const {
    return std::visit([&](const auto& lens) { return lens.project(pointCamera); }, lens_);
  }

  // Unit ray in the camera frame through a pixel; nullopt when the pixel is outside the lens's
  // valid image circle (fisheye) or the distortion cannot be inverted there.
  std::optional<cv::Vec3d> unproject(const cv::Point2d& pixel) const {
    return std::visit([&](const auto& lens) { return lens.unproject(pixel); }, lens_);
  }

  bool inImage(const cv::Point2d& pixel) const;
  // As given, with a wide-angle lens's maxFieldAngleRad cut to where its polynomial turns.
  const Intrinsics& intrinsics() const { return intrinsics_; }

  // Pixels per radian of ray angle at the optical axis, along the image's x and y: fx, fy for
  // pinhole and fisheye; for ocam the slope of rho(theta) there, through the affine matrix. For
  // thresholds and sampling densities (ocam has no focal length of its own).
  cv::Vec2d axisFocalPx() const {
    return std::visit([](const auto& lens) { return lens.axisFocalPx(); }, lens_);
  }

  // Where the radial polynomial stops increasing inside the field the lens asks for: beyond it
  // two rays would share a pixel, so the lens is taken to end there and the field is cut.
  struct FieldCut {
    double atRad;     // off-axis angle where the polynomial turns
    double askedRad;  // the field asked for (pinhole: the widest taken at all, about 84 degrees)
    bool inImage;     // the image reaches past the cut: part of the picture is lost
  };
  std::optional<FieldCut> fieldCut() const { return fieldCut_; }

 private:
  Intrinsics intrinsics_;
  Lens lens_;
  std::optional<FieldCut> fieldCut_;
};

}  // namespace surroundd::processing
