#include "daemon/config/vehicle_yaml.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "capture/file_source.hpp"
#include "render/gltf_car.hpp"

namespace surroundd::daemon {

namespace {

void readFootprint(YamlObject& v, VehicleConfig& c) {
  if (auto polygon = v.points("footprint", 3)) c.footprint = *polygon;
}

// Read whole here, so that a model that cannot be drawn is a config error, not a failed start.
void readModel(YamlObject& v, VehicleConfig& c) {
  if (!v.has("model")) return;
  c.model = v.existingFile("model").value_or("");
  if (c.model.empty()) return;
  try {
    render::loadGltfCar(c.model, c);
  } catch (const render::CarModelError& e) {
    v.error("model", e.what());
  }
}

// The box and the polygon are two ways to give one shape; the overhangs must leave a wheelbase.
void checkShape(YamlObject& v, const VehicleConfig& c) {
  if (!c.footprint.empty() && (v.has("length_m") || v.has("width_m"))) {
    v.error("footprint", "give either length_m and width_m or footprint, not both");
  }
  if (c.groundClearanceM >= c.heightM) {
    v.error("ground_clearance_m", fmt::format("expected less than height_m ({:g} m), got {:g}",
                                              c.heightM, c.groundClearanceM));
  }
  if (c.footprint.empty() && c.frontOverhangM + c.rearOverhangM >= c.lengthM) {
    v.error("front_overhang_m",
            fmt::format("the overhangs ({:g} + {:g} m) leave no wheelbase in length_m {:g}",
                        c.frontOverhangM, c.rearOverhangM, c.lengthM));
  }
  if (!c.footprint.empty() && (v.has("x_m") || v.has("y_m"))) {
    v.error("footprint", "a footprint is already in the vehicle frame: x_m and y_m do not apply");
  }
}

}  // namespace

const ConfigKeys<VehicleConfig>& vehicleKeys() {
  using Key = ConfigKey<VehicleConfig>;
  const NumberRange size{0.05, 30.0, false, "metres"};
  const NumberRange offset{-30.0, 30.0, false, "metres, vehicle frame"};
  const NumberRange overhang{0.0, 10.0, false, "metres"};
  static const ConfigKeys<VehicleConfig> kKeys{
      Key::number("length_m", &VehicleConfig::lengthM, size, "bumper to bumper"),
      Key::number("width_m", &VehicleConfig::widthM, size, "without mirrors"),
      Key::custom(
          "footprint", "a polygon instead of length_m and width_m", readFootprint,
          [](const VehicleConfig& a, const VehicleConfig& b) { return a.footprint == b.footprint; },
          {}, Shown::kExample),
      Key::number("height_m", &VehicleConfig::heightM, size, "the roof above the ground"),
      Key::number("ground_clearance_m", &VehicleConfig::groundClearanceM,
                  {0.0, 5.0, false, "metres"}, "the underside above the ground"),
      Key::number("front_overhang_m", &VehicleConfig::frontOverhangM, overhang,
                  "front bumper to front axle"),
      Key::number("rear_overhang_m", &VehicleConfig::rearOverhangM, overhang,
                  "rear axle to rear bumper"),
      Key::number("x_m", &VehicleConfig::xM, offset, "the body's centre, forward of the origin"),
      Key::number("y_m", &VehicleConfig::yM, offset, "the body's centre, left of the origin"),
      Key::number("margin_m", &VehicleConfig::marginM, overhang,
                  "the dark ground patch drawn around the model reaches this far out"),
      Key::number("track_m", &VehicleConfig::trackM, {0.0, 10.0, false, "metres"},
                  "between the wheels' centres, for the guidelines; 0: width_m less 0.25 m"),
      Key::number("steering_ratio", &VehicleConfig::steeringRatio, {3.0, 40.0, false, ""},
                  "steering-wheel angle over road-wheel angle, for the guidelines"),
      Key::flag("body_masks", &VehicleConfig::bodyMasks,
                "mask the body out of the cameras that see it"),
      Key::custom(
          "model",
          "the car's own 3D model drawn in the box instead of the procedural car: glTF 2.0 "
          "(.glb or .gltf), front towards +Z and +Y up, scaled to length_m, width_m and height_m",
          readModel,
          [](const VehicleConfig& a, const VehicleConfig& b) { return a.model == b.model; }, {},
          Shown::kExample),
  };
  return kKeys;
}

VehicleConfig readVehicle(YamlObject& v) {
  VehicleConfig c;
  vehicleKeys().read(v, c);
  checkShape(v, c);
  return c;
}

cv::Mat bodyMaskPicture(const std::filesystem::path& file) {
  cv::Mat grey;
  try {
    cv::cvtColor(capture::readPicture(file), grey, cv::COLOR_BGR2GRAY);
  } catch (const capture::CaptureError&) {
    return {};  // the caller names the file and what it expected
  }
  return grey;
}

BodyMaskConfig readBodyMask(YamlObject& m, cv::Size lensSize) {
  BodyMaskConfig c;
  c.mode =
      m.choice("mode", c.mode,
               {{"add", BodyMaskConfig::Mode::kAdd}, {"replace", BodyMaskConfig::Mode::kReplace}});
  if (m.has("file")) c.file = m.existingFile("file").value_or("");
  if (!c.file.empty()) {
    const cv::Mat picture = bodyMaskPicture(c.file);
    if (picture.size() != lensSize) {
      m.error("file",
              fmt::format("expected a {}x{} picture (the lens's size; white = body), got {}",
                          lensSize.width, lensSize.height,
                          picture.empty() ? std::string("none that can be read")
                                          : fmt::format("{}x{}", picture.cols, picture.rows)));
    }
  }
  if (auto polygons = m.pointLists("polygon", 3)) c.polygons = std::move(*polygons);
  if (!m.has("file") && !m.has("polygon")) {
    m.errorHere(
        "expected 'file' (a mask picture, white = body) and/or 'polygon' (pixels: one, or a list "
        "of them)");
  }
  m.finish();
  return c;
}

void emitVehicle(YAML::Emitter& out, const VehicleConfig& v) {
  out << YAML::Key << "vehicle" << YAML::Value << YAML::Flow << YAML::BeginMap;
  if (v.footprint.empty()) {
    out << YAML::Key << "length_m" << YAML::Value << v.lengthM;
    out << YAML::Key << "width_m" << YAML::Value << v.widthM;
    out << YAML::Key << "x_m" << YAML::Value << v.xM;
    out << YAML::Key << "y_m" << YAML::Value << v.yM;
  } else {
    out << YAML::Key << "footprint" << YAML::Value << YAML::BeginSeq;
    for (const auto& [x, y] : v.footprint)
      out << YAML::Flow << YAML::BeginSeq << x << y << YAML::EndSeq;
    out << YAML::EndSeq;
  }
  out << YAML::Key << "height_m" << YAML::Value << v.heightM;
  out << YAML::Key << "ground_clearance_m" << YAML::Value << v.groundClearanceM;
  out << YAML::Key << "front_overhang_m" << YAML::Value << v.frontOverhangM;
  out << YAML::Key << "rear_overhang_m" << YAML::Value << v.rearOverhangM;
  out << YAML::Key << "margin_m" << YAML::Value << v.marginM;
  out << YAML::Key << "track_m" << YAML::Value << v.trackM;
  out << YAML::Key << "steering_ratio" << YAML::Value << v.steeringRatio;
  out << YAML::Key << "body_masks" << YAML::Value << v.bodyMasks;
  if (!v.model.empty()) out << YAML::Key << "model" << YAML::Value << v.model.string();
  out << YAML::EndMap;
}

}  // namespace surroundd::daemon
