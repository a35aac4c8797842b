#include "processing/colour/correction_domain.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <numbers>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

namespace surroundd::processing {
namespace {

// A Dirichlet block needs this share of its pixels seen by both cameras; fewer would make its
// value the mean of a sliver.
constexpr double kMinimumSeenShare = 0.25;
// How far past a region the field is extended: the bicubic kernel's reach.
constexpr int kFillReach = 2;
// A bowl point this low is on its floor (the wall starts at height 0 and rises).
constexpr double kFloorHeightM = 1e-6;
// Ground seam data past the floor comes from rays at least this far below the horizon: nearer it
// the ground is too far away for a calibration's last tenth of a degree, and the horizon's
// objects and sky take over.
constexpr double kHorizonMarginRad = 1.0 * std::numbers::pi / 180;

struct BlockGrid {
  cv::Size size;
  int right(int b) const { return b % size.width == size.width - 1 ? b - size.width + 1 : b + 1; }
  int left(int b) const { return b % size.width == 0 ? b + size.width - 1 : b - 1; }
  // The 4-neighbours of a block (columns wrap, rows do not); -1 where there is none.
  std::array<int, 4> neighbours(int b) const {
    const int y = b / size.width;
    return {left(b), right(b), y > 0 ? b - size.width : -1,
            y + 1 < size.height ? b + size.width : -1};
  }
};

std::vector<int> componentOf(const BlockGrid& grid, const std::vector<std::uint8_t>& owner,
                             int seed, std::vector<bool>& visited) {
  std::vector<int> blocks{seed};
  visited[static_cast<std::size_t>(seed)] = true;
  for (std::size_t next = 0; next < blocks.size(); ++next) {
    for (const int q : grid.neighbours(blocks[next])) {
      if (q < 0 || visited[static_cast<std::size_t>(q)] ||
          owner[static_cast<std::size_t>(q)] != owner[static_cast<std::size_t>(seed)]) {
        continue;
      }
      visited[static_cast<std::size_t>(q)] = true;
      blocks.push_back(q);
    }
  }
  return blocks;
}

// First column of a region that may run across the +-180 degree column: the one after the
// widest run of columns it does not touch.
int firstColumn(const BlockGrid& grid, const std::vector<int>& blocks) {
  std::vector<bool> used(static_cast<std::size_t>(grid.size.width), false);
  for (const int b : blocks) used[static_cast<std::size_t>(b % grid.size.width)] = true;
  int bestStart = 0;
  int bestLength = 0;
  for (int start = 0; start < grid.size.width; ++start) {
    if (used[static_cast<std::size_t>(start)]) continue;
    int length = 0;
    while (length < grid.size.width &&
           !used[static_cast<std::size_t>((start + length) % grid.size.width)]) {
      ++length;
    }
    if (length > bestLength) {
      bestLength = length;
      bestStart = start;
    }
  }
  return (bestStart + bestLength) % grid.size.width;
}

}  // namespace

std::optional<int> correctionBlock(double scale, cv::Size panorama) {
  if (!(scale > 0 && scale <= 1)) return std::nullopt;
  const double side = 1 / scale;
  const auto block = std::lround(side);
  if (std::abs(side - static_cast<double>(block)) > 1e-9 || panorama.width % block != 0 ||
      panorama.height % block != 0) {
    return std::nullopt;
  }
  return static_cast<int>(block);
}

std::string correctionBlockProblem(double scale, cv::Size panorama) {
  return fmt::format(
      "must be 1/N with N dividing the panorama's {}x{} pixels (e.g. 0.25 or 0.125), got {:g}",
      panorama.width, panorama.height, scale);
}

CorrectionDomain buildCorrectionDomain(const Rig& rig, const PanoramaSettings& settings,
                                       const PanoramaLut& lut, double scale, bool groundSeams,
                                       std::span<const bool> present) {
  const auto tiling = correctionBlock(scale, lut.size);
  if (!tiling) {
    throw std::invalid_argument("colour correction scale " +
                                correctionBlockProblem(scale, lut.size));
  }
  const int block = *tiling;
  CorrectionDomain domain;
  domain.block = block;
  domain.grid = {lut.size.width / block, lut.size.height / block};
  for (const auto& camera : rig.cameras) {
    domain.sourceCameras.push_back(camera.role == ColourRole::kSource);
  }
  const BlockGrid grid{domain.grid};
  const int blocks = domain.grid.area();
  const auto isSource = [&](std::uint8_t camera) {
    return camera != PanoramaLut::kUnseen && domain.sourceCameras[camera];
  };
  const auto isPresent = [&](std::uint8_t camera) { return present.empty() || present[camera]; };
  for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
    if (isPresent(static_cast<std::uint8_t>(c))) continue;
    domain.notes.push_back(fmt::format("camera '{}' is missing: {}", rig.cameras[c].name,
                                       domain.sourceCameras[c]
                                           ? "its region is left uncorrected"
                                           : "its seams are free (Neumann) borders"));
  }

  std::vector<std::uint8_t> owner(static_cast<std::size_t>(blocks));
  for (int b = 0; b < blocks; ++b) {
    const int u = (b % domain.grid.width) * block + block / 2;
    const int v = (b / domain.grid.width) * block + block / 2;
    owner[static_cast<std::size_t>(b)] =
        lut.taps[static_cast<std::size_t>(v) * lut.size.width + u].camera;
  }

  const PanoramaProjector projector(rig, settings);
  const bool groundOnly = groundSeams && settings.projection == PanoramaProjection::kBowl;
  const cv::Vec3d& centre = settings.geometry.centre;
  // The pixels of block q that cameras `target` and `source` both see, as sample taps. Ground
  // only: the floor's pixels as the bowl puts them, and past the floor the ground itself where
  // the pixel's ray meets it (the wall stands for that ground, but each camera sees the wall's
  // point on a different piece of it). `beyondFloor`: most samples came from past the floor.
  const auto seamSamples = [&](int q, std::uint8_t target, std::uint8_t source, bool& beyondFloor) {
    const std::uint32_t first = static_cast<std::uint32_t>(domain.samples.size());
    const int u0 = (q % domain.grid.width) * block;
    const int v0 = (q / domain.grid.width) * block;
    std::size_t pastFloor = 0;
    for (int v = v0; v < v0 + block; ++v) {
      for (int u = u0; u < u0 + block; ++u) {
        const cv::Point2d pixel(u, v);
        std::optional<cv::Point2d> t;
        std::optional<cv::Point2d> s;
        if (groundOnly) {
          const cv::Vec3d direction = settings.geometry.direction(pixel);
          if (direction[2] > -std::sin(kHorizonMarginRad)) continue;
          cv::Vec3d point = projector.surfacePoint(pixel);
          const bool past = point[2] > kFloorHeightM;
          if (past) point = centre + direction * (-centre[2] / direction[2]);
          t = projector.cameraPixelOf(target, point);
          s = projector.cameraPixelOf(source, point);
          if (t && s && past) ++pastFloor;
        } else {
          t = projector.cameraPixel(target, pixel);
          s = projector.cameraPixel(source, pixel);
        }
        if (!t || !s) continue;
        domain.samples.push_back({encodeTap(*t, lut.cameraSizes[target], target),
                                  encodeTap(*s, lut.cameraSizes[source], source)});
      }
    }
    const std::size_t count = domain.samples.size() - first;
    if (static_cast<double>(count) < kMinimumSeenShare * block * block) {
      domain.samples.resize(first);
      return false;
    }
    beyondFloor = 2 * pastFloor > count;
    return true;
  };

  std::vector<bool> visited(static_cast<std::size_t>(blocks), false);
  for (int seed = 0; seed < blocks; ++seed) {
    if (visited[static_cast<std::size_t>(seed)] ||
        !isSource(owner[static_cast<std::size_t>(seed)])) {
      continue;
    }
    std::vector<int> members = componentOf(grid, owner, seed, visited);
    CorrectionRegion region;
    region.source = owner[static_cast<std::size_t>(seed)];
    if (!isPresent(region.source)) continue;
    // Row-major order in the region's own frame, columns unwrapped across +-180 degrees.
    const int x0 = firstColumn(grid, members);
    const auto localX = [&](int b) {
      return (b % domain.grid.width - x0 + domain.grid.width) % domain.grid.width;
    };
    int top = domain.grid.height;
    for (const int b : members) top = std::min(top, b / domain.grid.width);
    std::ranges::sort(members, {}, [&](int b) {
      return std::pair{b / domain.grid.width, localX(b)};
    });
    std::map<int, int> unknownOf;
    for (const int b : members) {
      unknownOf.emplace(b, static_cast<int>(region.blockOfUnknown.size()));
      region.blockOfUnknown.push_back(b);
      region.system.pixels.emplace_back(localX(b), b / domain.grid.width - top);
      region.system.size.width = std::max(region.system.size.width, localX(b) + 1);
      region.system.size.height =
          std::max(region.system.size.height, b / domain.grid.width - top + 1);
    }
    std::map<int, std::uint32_t> dirichletOfBlock;
    region.dirichletBegin.push_back(0);
    for (std::size_t i = 0; i < members.size(); ++i) {
      int degree = 0;
      for (const int q : grid.neighbours(members[i])) {
        if (q < 0) continue;
        if (const auto known = unknownOf.find(q); known != unknownOf.end()) {
          ++degree;
          if (static_cast<int>(i) < known->second)
            region.system.links.emplace_back(i, known->second);
          continue;
        }
        const std::uint8_t across = owner[static_cast<std::size_t>(q)];
        if (across == PanoramaLut::kUnseen || isSource(across) || !isPresent(across)) {
          continue;  // Neumann
        }
        auto found = dirichletOfBlock.find(q);
        if (found == dirichletOfBlock.end()) {
          const auto first = static_cast<std::uint32_t>(domain.samples.size());
          bool beyondFloor = false;
          if (!seamSamples(q, across, region.source, beyondFloor)) {
            continue;  // Neumann: too little overlap
          }
          found = dirichletOfBlock.emplace(q, static_cast<std::uint32_t>(region.dirichlet.size()))
                      .first;
          region.dirichlet.push_back(
              {q, across, first, static_cast<std::uint32_t>(domain.samples.size()), beyondFloor});
        }
        ++degree;
        region.dirichletOf.push_back(found->second);
      }
      region.system.degree.push_back(degree);
      region.dirichletBegin.push_back(static_cast<std::uint32_t>(region.dirichletOf.size()));
    }
    if (region.dirichlet.empty()) {
      domain.notes.push_back(fmt::format(
          "a region of {} blocks of camera '{}' has no seam with a target camera: left uncorrected",
          members.size(), rig.cameras[region.source].name));
      continue;
    }
    // The reverse of dirichletOf, and the seams: Dirichlet blocks were made in row-major order of
    // the region, which runs along a seam (seams are near-vertical in the panorama).
    std::vector<std::vector<std::uint32_t>> unknownsOf(region.dirichlet.size());
    for (std::uint32_t i = 0; i + 1 < region.dirichletBegin.size(); ++i) {
      for (auto k = region.dirichletBegin[i]; k < region.dirichletBegin[i + 1]; ++k) {
        unknownsOf[region.dirichletOf[k]].push_back(i);
      }
    }
    region.unknownsBegin.push_back(0);
    for (const auto& unknowns : unknownsOf) {
      region.unknownsOf.insert(region.unknownsOf.end(), unknowns.begin(), unknowns.end());
      region.unknownsBegin.push_back(static_cast<std::uint32_t>(region.unknownsOf.size()));
    }
    const auto regionIndex = static_cast<std::uint32_t>(domain.regions.size());
    for (std::uint32_t k = 0; k < region.dirichlet.size(); ++k) {
      const std::uint8_t target = region.dirichlet[k].target;
      auto seam = std::ranges::find_if(domain.seams, [&](const CorrectionSeam& s) {
        return s.region == regionIndex && s.target == target;
      });
      if (seam == domain.seams.end()) {
        domain.seams.push_back({regionIndex, target, {}});
        seam = domain.seams.end() - 1;
      }
      seam->blocks.push_back(k);
    }
    domain.regions.push_back(std::move(region));
  }

  // Field slots, and which slot each block shows.
  domain.fillFrom.assign(static_cast<std::size_t>(blocks), -1);
  std::deque<std::pair<int, int>> frontier;  // block, distance from a region
  for (const auto& region : domain.regions) {
    domain.firstUnknownSlot.push_back(static_cast<std::uint32_t>(domain.slots));
    for (const int b : region.blockOfUnknown) {
      domain.fillFrom[static_cast<std::size_t>(b)] = static_cast<int>(domain.slots++);
      frontier.emplace_back(b, 0);
    }
  }
  for (const auto& region : domain.regions) {
    domain.firstDirichletSlot.push_back(static_cast<std::uint32_t>(domain.slots));
    for (const auto& d : region.dirichlet) {
      domain.fillFrom[static_cast<std::size_t>(d.block)] = static_cast<int>(domain.slots++);
      frontier.emplace_back(d.block, 0);
    }
  }
  while (!frontier.empty()) {
    const auto [b, distance] = frontier.front();
    frontier.pop_front();
    if (distance == kFillReach) continue;
    for (const int q : grid.neighbours(b)) {
      if (q < 0 || domain.fillFrom[static_cast<std::size_t>(q)] >= 0) continue;
      domain.fillFrom[static_cast<std::size_t>(q)] = domain.fillFrom[static_cast<std::size_t>(b)];
      frontier.emplace_back(q, distance + 1);
    }
  }

  // Each pixel's weight of source cameras: whole where a source owns it, the blend weight across
  // a seam with a target.
  domain.share.assign(lut.taps.size(), 0);
  for (std::size_t i = 0; i < lut.taps.size(); ++i) {
    if (isSource(lut.taps[i].camera)) domain.share[i] = 256;
  }
  for (const auto& blend : lut.blendTaps) {
    const bool ownerIsSource = isSource(lut.taps[blend.pixel].camera);
    if (ownerIsSource != isSource(blend.tap.camera)) {
      domain.share[blend.pixel] =
          static_cast<std::uint16_t>(ownerIsSource ? 256 - blend.tap.weight : blend.tap.weight);
    }
  }
  return domain;
}

}  // namespace surroundd::processing
