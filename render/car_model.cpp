#include "render/car_model.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include <opencv2/core.hpp>

#include "render/gltf_car.hpp"

namespace surroundd::render {
namespace {

using Colour = std::array<float, 3>;
constexpr Colour kBody{0.16F, 0.32F, 0.58F};
constexpr Colour kGlass{0.10F, 0.12F, 0.15F};
constexpr Colour kTyre{0.06F, 0.06F, 0.06F};
constexpr Colour kFootprint{0.03F, 0.03F, 0.03F};
constexpr Colour kHeadlight{0.95F, 0.92F, 0.75F};
constexpr Colour kTaillight{0.80F, 0.06F, 0.04F};

class CarBuilder {
 public:
  explicit CarBuilder(std::vector<CarVertex>& out) : out_(out) {}

  // A planar polygon of 3 or 4 corners, its normal turned away from `inside`.
  void face(std::initializer_list<cv::Vec3f> corners, const Colour& colour,
            const cv::Vec3f& inside) {
    const std::vector<cv::Vec3f> p(corners);
    cv::Vec3f normal = cv::normalize((p[1] - p[0]).cross(p[2] - p[0]));
    cv::Vec3f centre(0, 0, 0);
    for (const auto& corner : p) centre += corner / static_cast<float>(p.size());
    if (normal.dot(centre - inside) < 0) normal = -normal;
    for (std::size_t k = 1; k + 1 < p.size(); ++k) {
      for (const auto& corner : {p[0], p[k], p[k + 1]}) {
        out_.push_back({{corner[0], corner[1], corner[2]},
                        {normal[0], normal[1], normal[2]},
                        {colour[0], colour[1], colour[2]},
                        {0, 0}});
      }
    }
  }

  // A solid between two horizontal rectangles (lo, hi: x and y extents at z0 and z1).
  void frustum(const cv::Vec4f& bottom, float z0, const cv::Vec4f& top, float z1,
               const Colour& colour) {
    const auto corner = [](const cv::Vec4f& r, int k, float z) {
      const float x = (k == 1 || k == 2) ? r[1] : r[0];
      const float y = (k >= 2) ? r[3] : r[2];
      return cv::Vec3f(x, y, z);
    };
    const cv::Vec3f inside((bottom[0] + bottom[1]) / 2, (bottom[2] + bottom[3]) / 2, (z0 + z1) / 2);
    for (int k = 0; k < 4; ++k) {
      const int n = (k + 1) % 4;
      face({corner(bottom, k, z0), corner(bottom, n, z0), corner(top, n, z1), corner(top, k, z1)},
           colour, inside);
    }
    face({corner(bottom, 0, z0), corner(bottom, 1, z0), corner(bottom, 2, z0),
          corner(bottom, 3, z0)},
         colour, inside);
    face({corner(top, 0, z1), corner(top, 1, z1), corner(top, 2, z1), corner(top, 3, z1)}, colour,
         inside);
  }

  void box(const cv::Vec4f& extent, float z0, float z1, const Colour& colour) {
    frustum(extent, z0, extent, z1, colour);
  }

  // A wheel: a cylinder along y.
  void wheel(float x, float y, float radius, float width) {
    constexpr int kSides = 16;
    const cv::Vec3f centre(x, y, radius);
    for (int k = 0; k < kSides; ++k) {
      const auto at = [&](int i, float side) {
        const double a = 2 * std::numbers::pi * i / kSides;
        return cv::Vec3f(x + radius * static_cast<float>(std::cos(a)), y + side,
                         radius + radius * static_cast<float>(std::sin(a)));
      };
      const float h = width / 2;
      face({at(k, -h), at(k + 1, -h), at(k + 1, h), at(k, h)}, kTyre, centre);
      face({cv::Vec3f(x, y - h, radius), at(k, -h), at(k + 1, -h)}, kTyre,
           centre + cv::Vec3f(0, h, 0));
      face({cv::Vec3f(x, y + h, radius), at(k, h), at(k + 1, h)}, kTyre,
           centre - cv::Vec3f(0, h, 0));
    }
  }

 private:
  std::vector<CarVertex>& out_;
};

}  // namespace

CarModel buildCarModel(const processing::VehicleDimensions& car, double footprintRadiusM) {
  CarModel model;
  if (!car.model.empty()) model = loadGltfCar(car.model, car);
  std::vector<CarVertex>& vertices = model.vertices;
  const std::size_t first = vertices.size();
  CarBuilder build(vertices);
  const processing::VehicleDimensions::Box box = car.box();
  const auto l = static_cast<float>(box.lengthM / 2);
  const auto w = static_cast<float>(box.widthM / 2);
  const auto h = static_cast<float>(car.heightM);
  const auto cx = static_cast<float>(box.centreXM);
  const auto cy = static_cast<float>(box.centreYM);
  const auto margin = static_cast<float>(car.marginM);
  const auto ring = static_cast<float>(footprintRadiusM) + 0.05F;

  // Footprint, just above the ground so that it wins the depth test against the floor.
  const float x0 = std::min(cx - l - margin, -ring);
  const float x1 = std::max(cx + l + margin, ring);
  const float y0 = std::min(cy - w - margin, -ring);
  const float y1 = std::max(cy + w + margin, ring);
  build.face({{x0, y0, 0.01F}, {x1, y0, 0.01F}, {x1, y1, 0.01F}, {x0, y1, 0.01F}}, kFootprint,
             {0, 0, -1});
  if (!car.model.empty()) {
    model.parts.push_back({first, vertices.size() - first, -1});
    return model;
  }

  const float wheelRadius = std::min({0.34F, h * 0.23F, l * 0.3F});
  const float sill = std::max(static_cast<float>(car.groundClearanceM), wheelRadius * 0.9F);
  const float belt = sill + (h - sill) * 0.45F;
  build.box({cx - l, cx + l, cy - w, cy + w}, sill, belt, kBody);
  // Cabin: narrower and shorter at the roof, set back from the bonnet.
  build.frustum({cx - l + 0.35F * l, cx + l - 0.55F * l, cy - w + 0.06F * w, cy + w - 0.06F * w},
                belt, {cx - l + 0.5F * l, cx + l - 0.85F * l, cy - w + 0.2F * w, cy + w - 0.2F * w},
                h, kGlass);
  const float frontAxle = cx + l - static_cast<float>(car.frontOverhangM);
  const float rearAxle = cx - l + static_cast<float>(car.rearOverhangM);
  const float tyre = std::min(0.24F, w * 0.25F);
  for (const float sx : {-1.0F, 1.0F}) {
    for (const float sy : {-1.0F, 1.0F}) {
      build.wheel(sx > 0 ? frontAxle : rearAxle, cy + sy * (w - tyre / 2), wheelRadius, tyre);
    }
    // Lights across the front and back faces.
    const Colour& light = sx > 0 ? kHeadlight : kTaillight;
    const float face = cx + sx * (l + 0.01F);
    for (const float sy : {-1.0F, 1.0F}) {
      build.face({{face, cy + sy * w * 0.9F, belt - (belt - sill) * 0.35F},
                  {face, cy + sy * w * 0.55F, belt - (belt - sill) * 0.35F},
                  {face, cy + sy * w * 0.55F, belt - (belt - sill) * 0.1F},
                  {face, cy + sy * w * 0.9F, belt - (belt - sill) * 0.1F}},
                 light, {cx, cy, (belt + sill) / 2});
    }
  }
  model.parts.push_back({first, vertices.size() - first, -1});
  return model;
}

}  // namespace surroundd::render
