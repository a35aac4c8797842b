#include "daemon/vehicle_yaml.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

namespace surroundd::daemon {

processing::VehicleBody VehicleConfig::body() const {
  if (footprint.empty()) {
    return processing::boxBody(lengthM, widthM, heightM, groundClearanceM, {xM, yM});
  }
  processing::VehicleBody body{{}, groundClearanceM, heightM};
  for (const auto& [x, y] : footprint) body.footprint.emplace_back(x, y);
  return body;
}

render::CarDimensions VehicleConfig::car() const {
  render::CarDimensions car;
  car.heightM = heightM;
  car.groundClearanceM = groundClearanceM;
  car.frontOverhangM = frontOverhangM;
  car.rearOverhangM = rearOverhangM;
  car.marginM = marginM;
  // The model is a box car: a footprint polygon draws as its bounding box.
  const auto corners = body().footprint;
  double minX = corners[0].x, maxX = minX, minY = corners[0].y, maxY = minY;
  for (const auto& p : corners) {
    minX = std::min(minX, p.x), maxX = std::max(maxX, p.x);
    minY = std::min(minY, p.y), maxY = std::max(maxY, p.y);
  }
  car.lengthM = maxX - minX;
  car.widthM = maxY - minY;
  car.centreXM = (minX + maxX) / 2;
  car.centreYM = (minY + maxY) / 2;
  return car;
}

double VehicleConfig::reachM() const {
  double reach = 0;
  for (const auto& p : body().footprint) reach = std::max(reach, std::hypot(p.x, p.y));
  return reach;
}

VehicleConfig readVehicle(YamlObject& v) {
  VehicleConfig c;
  const NumberRange size{0.05, 30.0, false, "metres"};
  const NumberRange offset{-30.0, 30.0, false, "metres, vehicle frame"};
  if (auto polygon = v.points("footprint", 3)) {
    if (v.has("length_m") || v.has("width_m")) {
      v.error("footprint", "give either length_m and width_m or footprint, not both");
    }
    c.footprint = *polygon;
  } else {
    c.lengthM = v.number("length_m", c.lengthM, size);
    c.widthM = v.number("width_m", c.widthM, size);
  }
  c.heightM = v.number("height_m", c.heightM, size);
  c.groundClearanceM =
      v.number("ground_clearance_m", c.groundClearanceM, {0.0, 5.0, false, "metres"});
  if (c.groundClearanceM >= c.heightM) {
    v.error("ground_clearance_m", fmt::format("expected less than height_m ({:g} m), got {:g}",
                                              c.heightM, c.groundClearanceM));
  }
  c.frontOverhangM = v.number("front_overhang_m", c.frontOverhangM, {0.0, 10.0, false, "metres"});
  c.rearOverhangM = v.number("rear_overhang_m", c.rearOverhangM, {0.0, 10.0, false, "metres"});
  if (c.footprint.empty() && c.frontOverhangM + c.rearOverhangM >= c.lengthM) {
    v.error("front_overhang_m",
            fmt::format("the overhangs ({:g} + {:g} m) leave no wheelbase in length_m {:g}",
                        c.frontOverhangM, c.rearOverhangM, c.lengthM));
  }
  c.xM = v.number("x_m", c.xM, offset);
  c.yM = v.number("y_m", c.yM, offset);
  if (!c.footprint.empty() && (v.has("x_m") || v.has("y_m"))) {
    v.error("footprint", "a footprint is already in the vehicle frame: x_m and y_m do not apply");
  }
  c.marginM = v.number("margin_m", c.marginM, {0.0, 10.0, false, "metres"});
  c.bodyMasks = v.boolean("body_masks", c.bodyMasks);
  v.finish();
  return c;
}

BodyMaskConfig readBodyMask(YamlObject& m, cv::Size lensSize) {
  BodyMaskConfig c;
  c.mode =
      m.choice("mode", c.mode,
               {{"add", BodyMaskConfig::Mode::kAdd}, {"replace", BodyMaskConfig::Mode::kReplace}});
  if (m.has("file")) c.file = m.existingFile("file").value_or("");
  if (!c.file.empty()) {
    const cv::Mat picture = cv::imread(c.file.string(), cv::IMREAD_GRAYSCALE);
    if (picture.size() != lensSize) {
      m.error("file",
              fmt::format("expected a {}x{} picture (the lens's size; white = body), got {}",
                          lensSize.width, lensSize.height,
                          picture.empty() ? std::string("none that can be read")
                                          : fmt::format("{}x{}", picture.cols, picture.rows)));
    }
  }
  if (auto polygon = m.points("polygon", 3)) c.polygon = *polygon;
  if (!m.has("file") && !m.has("polygon")) {
    m.errorHere("expected 'file' (a mask picture, white = body) and/or 'polygon' (pixels)");
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
  out << YAML::Key << "body_masks" << YAML::Value << v.bodyMasks;
  out << YAML::EndMap;
}

}  // namespace surroundd::daemon
