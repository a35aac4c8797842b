#include "processing/vehicle_dimensions.hpp"

#include <algorithm>
#include <cmath>

namespace surroundd::processing {

VehicleBody VehicleDimensions::body() const {
  if (footprint.empty()) {
    return boxBody(lengthM, widthM, heightM, groundClearanceM, {xM, yM});
  }
  VehicleBody body{{}, groundClearanceM, heightM};
  for (const auto& [x, y] : footprint) body.footprint.emplace_back(x, y);
  return body;
}

VehicleDimensions::Box VehicleDimensions::box() const {
  // Without allocating: the guidelines ask for it at every point of their paths.
  if (footprint.empty()) return {lengthM, widthM, xM, yM};
  double minX = footprint[0][0], maxX = minX, minY = footprint[0][1], maxY = minY;
  for (const auto& [x, y] : footprint) {
    minX = std::min(minX, x), maxX = std::max(maxX, x);
    minY = std::min(minY, y), maxY = std::max(maxY, y);
  }
  return {maxX - minX, maxY - minY, (minX + maxX) / 2, (minY + maxY) / 2};
}

double VehicleDimensions::wheelTrackM() const {
  return trackM > 0 ? trackM : std::max(0.1, box().widthM - 0.25);
}

double VehicleDimensions::reachM() const {
  double reach = 0;
  for (const auto& p : body().footprint) reach = std::max(reach, std::hypot(p.x, p.y));
  return reach;
}

}  // namespace surroundd::processing
