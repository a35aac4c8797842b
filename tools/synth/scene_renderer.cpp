#include "tools/synth/scene_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "processing/lens/camera_model.hpp"

namespace surroundd::synth {
namespace {

float angleBetween(const cv::Vec3f& a, const cv::Vec3f& b) {
  // Chord length is accurate for the small angles between neighbouring pixels.
  const cv::Vec3f d = a - b;
  return 2 * std::asin(std::min(1.0f, 0.5f * std::sqrt(d.dot(d))));
}

// Stack-sized chunk of a row: no allocation in the render loop.
constexpr int kChunk = CameraRays::kTileSize;

}  // namespace

CameraRays::CameraRays(const processing::CameraCalibration& camera, const EgoBody* body)
    : size_(camera.intrinsics.imageSize),
      position_(camera.pose.position),
      fisheye_(processing::isWideAngle(camera.intrinsics.model)),
      pixels_(static_cast<std::size_t>(size_.area())),
      offAxis_(size_, CV_32F) {
  const processing::CameraModel model(camera.intrinsics);
  const cv::Matx33d rotation = camera.pose.rotation;
  // Rays first (the unprojection is the expensive part), footprints from neighbours after.
  cv::parallel_for_(cv::Range(0, size_.height), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      auto* angle = offAxis_.ptr<float>(y);
      for (int x = 0; x < size_.width; ++x) {
        Pixel& p = pixels_[static_cast<std::size_t>(y * size_.width + x)];
        const auto ray = model.unproject({static_cast<double>(x), static_cast<double>(y)});
        p.pixelAngle = -1;
        p.groundDistance = -1;
        p.groundLod = 0;
        p.body = -1;
        angle[x] = -1;
        if (!ray) continue;
        p.direction = cv::Vec3f(cv::normalize(rotation * *ray));
        p.pixelAngle = 0;
        angle[x] = static_cast<float>(std::acos(std::clamp((*ray)[2], -1.0, 1.0)));
      }
    }
  });
  const auto at = [&](int x, int y) -> const Pixel* {
    if (x < 0 || y < 0 || x >= size_.width || y >= size_.height) return nullptr;
    const Pixel& p = pixels_[static_cast<std::size_t>(y * size_.width + x)];
    return p.pixelAngle < 0 ? nullptr : &p;
  };
  const float height = static_cast<float>(camera.pose.position[2]);
  const float fallbackAngle = static_cast<float>(1.0 / model.axisFocalPx()[0]);
  for (int y = 0; y < size_.height; ++y) {
    for (int x = 0; x < size_.width; ++x) {
      Pixel& p = pixels_[static_cast<std::size_t>(y * size_.width + x)];
      if (p.pixelAngle < 0) continue;
      float angle = 0;
      for (const auto& [nx, ny] : {std::pair{x + 1, y}, {x - 1, y}, {x, y + 1}, {x, y - 1}}) {
        if (const Pixel* n = at(nx, ny))
          angle = std::max(angle, angleBetween(p.direction, n->direction));
      }
      p.pixelAngle = angle > 0 ? angle : fallbackAngle;
      if (p.direction[2] < -1e-6f && height > 0) {
        p.groundDistance = height / -p.direction[2];
        p.groundLod = Scene::groundLodFor(p.groundDistance, p.pixelAngle, p.direction[2]);
      }
    }
  }
  // The body stands between the camera and everything else the ray could meet (it is on the
  // vehicle, the scene is not), so a pixel that sees it sees nothing else.
  if (body != nullptr) {
    // Rows in parallel, each with its own list, joined in row order: the same indices for any
    // number of threads.
    std::vector<std::vector<BodyHit>> rowHits(static_cast<std::size_t>(size_.height));
    const cv::Vec3d origin = camera.pose.position;
    cv::parallel_for_(cv::Range(0, size_.height), [&](const cv::Range& rows) {
      for (int y = rows.start; y < rows.end; ++y) {
        auto& hits = rowHits[static_cast<std::size_t>(y)];
        Pixel* pixels = pixels_.data() + static_cast<std::ptrdiff_t>(y) * size_.width;
        for (int x = 0; x < size_.width; ++x) {
          Pixel& p = pixels[x];
          if (p.pixelAngle < 0) continue;
          if (const auto hit = body->intersect(origin, cv::Vec3d(p.direction), p.pixelAngle)) {
            p.body = static_cast<std::int32_t>(hits.size());
            hits.push_back(*hit);
          }
        }
      }
    });
    for (int y = 0; y < size_.height; ++y) {
      const auto first = static_cast<std::int32_t>(bodyHits_.size());
      Pixel* pixels = pixels_.data() + static_cast<std::ptrdiff_t>(y) * size_.width;
      for (int x = 0; x < size_.width; ++x) {
        if (pixels[x].body >= 0) pixels[x].body += first;
      }
      const auto& hits = rowHits[static_cast<std::size_t>(y)];
      bodyHits_.insert(bodyHits_.end(), hits.begin(), hits.end());
    }
  }
  // Tile cones: the smallest cone around the tile's rays we bother to find (mean axis, widest ray),
  // widened by a pixel so that a box edge at the tile border is never culled.
  tilesX_ = (size_.width + kTileSize - 1) / kTileSize;
  const int tilesY = (size_.height + kTileSize - 1) / kTileSize;
  tiles_.resize(static_cast<std::size_t>(tilesX_ * tilesY));
  for (int ty = 0; ty < tilesY; ++ty) {
    for (int tx = 0; tx < tilesX_; ++tx) {
      Tile& tile = tiles_[static_cast<std::size_t>(ty * tilesX_ + tx)];
      cv::Vec3f sum(0, 0, 0);
      float widest = 0;
      const int x1 = std::min(size_.width, (tx + 1) * kTileSize);
      const int y1 = std::min(size_.height, (ty + 1) * kTileSize);
      for (int y = ty * kTileSize; y < y1; ++y) {
        for (int x = tx * kTileSize; x < x1; ++x) {
          if (const Pixel* p = at(x, y)) {
            sum += p->direction;
            widest = std::max(widest, p->pixelAngle);
          }
        }
      }
      if (sum.dot(sum) == 0) continue;
      tile.empty = false;
      tile.axis = cv::normalize(sum);
      float half = 0;
      for (int y = ty * kTileSize; y < y1; ++y) {
        for (int x = tx * kTileSize; x < x1; ++x) {
          if (const Pixel* p = at(x, y))
            half = std::max(half, angleBetween(tile.axis, p->direction));
        }
      }
      half = std::min(half + 2 * widest, static_cast<float>(std::numbers::pi));
      tile.halfAngle = half;
      tile.cosHalfAngle = std::cos(half);
      tile.sinHalfAngle = std::sin(half);
      tile.reflects = reflectionCone(tx * kTileSize, x1, ty * kTileSize, y1, tile.reflections);
    }
  }
}

bool CameraRays::reflectionCone(int x0, int x1, int y0, int y1, Cone& cone) const {
  cv::Vec3f apex(0, 0, 0), sum(0, 0, 0);
  int count = 0;
  float widest = 0;
  const auto forEachHit = [&](auto&& f) {
    for (int y = y0; y < y1; ++y) {
      for (int x = x0; x < x1; ++x) {
        const std::int32_t i = row(y)[x].body;
        if (i >= 0) f(bodyHits_[static_cast<std::size_t>(i)]);
      }
    }
  };
  forEachHit([&](const BodyHit& hit) {
    apex += hit.point;
    sum += hit.reflected;
    widest = std::max(widest, hit.spread);
    ++count;
  });
  if (count == 0) return false;
  cone.apex = apex / count;
  cone.axis = sum.dot(sum) > 0 ? cv::normalize(sum) : cv::Vec3f(0, 0, 1);
  float half = 0;
  forEachHit([&](const BodyHit& hit) {
    const cv::Vec3f d = hit.point - cone.apex;
    cone.radius = std::max(cone.radius, std::sqrt(d.dot(d)));
    half = std::max(half, angleBetween(cone.axis, hit.reflected));
  });
  // Widened like the tiles' own cones, and by a millimetre and a milliradian for the float
  // rounding of the rays that are built from these per frame.
  cone.radius += 1e-3f;
  half = std::min(half + 2 * widest + 1e-3f, static_cast<float>(std::numbers::pi));
  cone.halfAngle = half;
  cone.cosHalfAngle = std::cos(half);
  cone.sinHalfAngle = std::sin(half);
  return true;
}

cv::Mat CameraRays::bodyMask() const {
  cv::Mat mask(size_, CV_8U);
  for (int y = 0; y < size_.height; ++y) {
    const Pixel* pixels = row(y);
    auto* out = mask.ptr<std::uint8_t>(y);
    for (int x = 0; x < size_.width; ++x) out[x] = pixels[x].body >= 0 ? 255 : 0;
  }
  return mask;
}

void SceneRenderer::cullBoxes(const VehiclePose& pose, const CameraRays& rays,
                              std::vector<std::uint32_t>& masks,
                              std::vector<std::uint32_t>& reflectionMasks) {
  const auto& tiles = rays.tiles();
  masks.assign(tiles.size(), 0U);  // same size every frame: no reallocation after the first
  const bool reflections = !rays.bodyHits().empty();
  reflectionMasks.assign(reflections ? tiles.size() : 0, 0U);
  const cv::Vec3d origin = pose.toWorld(cv::Vec3d(rays.position()));
  const auto& boxes = scene_.boxes();
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const SceneBox& box = boxes[i];
    const std::uint32_t bit = 1U << i;
    // Box centre relative to the camera, in the vehicle frame where the tile axes live.
    const cv::Vec3d centre(box.centre.x, box.centre.y, box.halfSize[2] * 0.5);
    const cv::Vec3d centreVehicle = pose.toVehicle(centre);
    const cv::Vec3d rel = centreVehicle - pose.toVehicle(origin);
    const double distance = cv::norm(rel);
    const double radius = box.boundingRadius;
    if (distance <= radius * 1.01) {
      for (auto& mask : masks) mask |= bit;
    } else {
      const cv::Vec3f u(rel / distance);
      const float beta = static_cast<float>(std::asin(radius / distance));
      const float cosBeta = std::cos(beta), sinBeta = std::sin(beta);
      for (std::size_t t = 0; t < tiles.size(); ++t) {
        const auto& tile = tiles[t];
        if (tile.empty) continue;
        if (tile.halfAngle + beta >= static_cast<float>(std::numbers::pi) ||
            tile.axis.dot(u) >= tile.cosHalfAngle * cosBeta - tile.sinHalfAngle * sinBeta) {
          masks[t] |= bit;
        }
      }
    }
    if (!reflections) continue;
    // The same test for the reflections, from each tile's spread of reflection points: the box's
    // sphere grows by that spread.
    for (std::size_t t = 0; t < tiles.size(); ++t) {
      const CameraRays::Cone& cone = tiles[t].reflections;
      if (!tiles[t].reflects) continue;
      const cv::Vec3d relReflection = centreVehicle - cv::Vec3d(cone.apex);
      const double d = cv::norm(relReflection);
      const double r = radius + cone.radius;
      if (d <= r * 1.01) {
        reflectionMasks[t] |= bit;
        continue;
      }
      const cv::Vec3f u(relReflection / d);
      const float beta = static_cast<float>(std::asin(r / d));
      if (cone.halfAngle + beta >= static_cast<float>(std::numbers::pi) ||
          cone.axis.dot(u) >=
              cone.cosHalfAngle * std::cos(beta) - cone.sinHalfAngle * std::sin(beta)) {
        reflectionMasks[t] |= bit;
      }
    }
  }
}

void SceneRenderer::render(const VehiclePose& pose, std::vector<CameraJob>& jobs) {
  tileMasks_.resize(jobs.size());
  reflectionMasks_.resize(jobs.size());
  firstRow_.assign(jobs.size() + 1, 0);
  origins_.resize(jobs.size());
  auto& firstRow = firstRow_;
  auto& origins = origins_;
  for (std::size_t j = 0; j < jobs.size(); ++j) {
    cullBoxes(pose, *jobs[j].rays, tileMasks_[j], reflectionMasks_[j]);
    origins[j] = cv::Vec3f(pose.toWorld(cv::Vec3d(jobs[j].rays->position())));
    firstRow[j + 1] = firstRow[j] + jobs[j].rays->size().height;
  }
  const float c = static_cast<float>(std::cos(pose.yaw));
  const float s = static_cast<float>(std::sin(pose.yaw));
  cv::parallel_for_(cv::Range(0, firstRow.back()), [&](const cv::Range& range) {
    cv::Vec3f radiance[kChunk];
    for (int r = range.start; r < range.end; ++r) {
      std::size_t j = 0;
      while (r >= firstRow[j + 1]) ++j;
      const CameraJob& job = jobs[j];
      const int y = r - firstRow[j];
      const int width = job.rays->size().width;
      const CameraRays::Pixel* pixels = job.rays->row(y);
      const std::uint32_t* masks =
          tileMasks_[j].data() +
          static_cast<std::ptrdiff_t>(y / CameraRays::kTileSize) * job.rays->tilesX();
      // Only read for body pixels, which only a camera with reflection masks has.
      const std::uint32_t* reflectionMasks =
          reflectionMasks_[j].empty()
              ? nullptr
              : reflectionMasks_[j].data() +
                    static_cast<std::ptrdiff_t>(y / CameraRays::kTileSize) * job.rays->tilesX();
      auto* out = job.out->ptr<cv::Vec3b>(y);
      RayQuery query;
      query.origin = origins[j];
      for (int x0 = 0; x0 < width; x0 += kChunk) {
        const int count = std::min(kChunk, width - x0);
        query.boxMask = masks[x0 / CameraRays::kTileSize];
        for (int i = 0; i < count; ++i) {
          const CameraRays::Pixel& p = pixels[x0 + i];
          if (p.pixelAngle < 0) {
            radiance[i] = cv::Vec3f(0, 0, 0);
            continue;
          }
          if (p.body >= 0) {
            radiance[i] = bodyRadiance(job.rays->bodyHits()[static_cast<std::size_t>(p.body)], pose,
                                       c, s, reflectionMasks[x0 / CameraRays::kTileSize]);
            continue;
          }
          const cv::Vec3f& d = p.direction;
          query.direction = cv::Vec3f(c * d[0] - s * d[1], s * d[0] + c * d[1], d[2]);
          if (query.boxMask == 0 && p.groundDistance > 0) {
            const float gx = query.origin[0] + p.groundDistance * query.direction[0];
            const float gy = query.origin[1] + p.groundDistance * query.direction[1];
            if (scene_.insideYard(gx, gy)) {
              radiance[i] = scene_.groundAt(gx, gy, p.groundLod);
              continue;
            }
          }
          query.pixelAngle = p.pixelAngle;
          query.groundDistance = p.groundDistance;
          query.groundLod = p.groundLod;
          radiance[i] = scene_.radiance(query);
        }
        job.photometrics->convertRow(job.frame, radiance, out + x0, y, x0, count);
      }
    }
  });
}

cv::Vec3f SceneRenderer::bodyRadiance(const BodyHit& hit, const VehiclePose& pose, float c, float s,
                                      std::uint32_t boxMask) const {
  const auto turn = [&](const cv::Vec3f& v) {
    return cv::Vec3f(c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]);
  };
  RayQuery query;
  query.origin =
      turn(hit.point) + cv::Vec3f(static_cast<float>(pose.x), static_cast<float>(pose.y), 0);
  query.direction = turn(hit.reflected);
  query.pixelAngle = hit.spread;
  query.boxMask = boxMask;
  // The body is convex: its reflection never meets it again.
  const cv::Vec3f reflected = hit.mirror > 0 ? scene_.radiance(query) : cv::Vec3f(0, 0, 0);
  return EgoBody::shade(hit, turn(hit.normal), reflected);
}

cv::Mat SceneRenderer::panorama(const VehiclePose& pose, const cv::Vec3d& centre,
                                cv::Size size) const {
  cv::Mat out(size, CV_8UC3);
  const cv::Vec3f origin(pose.toWorld(centre));
  const double pi = std::numbers::pi;
  cv::parallel_for_(cv::Range(0, size.height), [&](const cv::Range& rows) {
    for (int v = rows.start; v < rows.end; ++v) {
      // Row centre v + 0.5 maps to elevation 30 deg - (v + 0.5) / H * 90 deg.
      const double elevation = pi / 6 - (v + 0.5) / size.height * (pi / 2);
      auto* px = out.ptr<cv::Vec3b>(v);
      for (int u = 0; u < size.width; ++u) {
        const double azimuth = (u + 0.5) / size.width * 2 * pi - pi;
        const cv::Vec3d dirVehicle(std::cos(elevation) * std::cos(azimuth),
                                   std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
        RayQuery query;
        query.origin = origin;
        query.direction = cv::Vec3f(pose.directionToWorld(dirVehicle));
        query.pixelAngle = static_cast<float>(
            std::max(2 * pi / size.width * std::cos(elevation), pi / 2 / size.height));
        const cv::Vec3f radiance = scene_.radiance(query);
        px[u] =
            cv::Vec3b(cv::saturate_cast<uchar>(radiance[0]), cv::saturate_cast<uchar>(radiance[1]),
                      cv::saturate_cast<uchar>(radiance[2]));
      }
    }
  });
  return out;
}

}  // namespace surroundd::synth
