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

// The steps of buildCorrectionDomain, in the order it runs them; each fills its part of `domain`
// from what the steps before it made.
class DomainBuilder {
 public:
  DomainBuilder(const Rig& rig, const PanoramaSettings& settings, const PanoramaLut& lut, int block,
                bool groundSeams, std::span<const bool> present)
      : rig_(rig),
        settings_(settings),
        lut_(lut),
        present_(present),
        projector_(rig, settings),
        groundOnly_(groundSeams && settings.projection == PanoramaProjection::kBowl) {
    domain_.block = block;
    domain_.grid = {lut.size.width / block, lut.size.height / block};
    grid_ = BlockGrid{domain_.grid};
    for (const auto& camera : rig.cameras) {
      domain_.sourceCameras.push_back(camera.role == ColourRole::kSource);
    }
  }

  CorrectionDomain build() && {
    noteMissingCameras();
    findBlockOwners();
    findRegions();
    assignFieldSlots();
    weighSources();
    return std::move(domain_);
  }

 private:
  int blockCount() const { return domain_.grid.area(); }
  int column(int b) const { return b % domain_.grid.width; }
  int row(int b) const { return b / domain_.grid.width; }
  bool isSource(std::uint8_t camera) const {
    return camera != PanoramaLut::kUnseen && domain_.sourceCameras[camera];
  }
  bool isPresent(std::uint8_t camera) const { return present_.empty() || present_[camera]; }

  // A missing camera changes the domain without an error (the rest is still corrected): the log
  // says what it costs.
  void noteMissingCameras() {
    for (std::size_t c = 0; c < rig_.cameras.size(); ++c) {
      if (isPresent(static_cast<std::uint8_t>(c))) continue;
      domain_.notes.push_back(fmt::format("camera '{}' is missing: {}", rig_.cameras[c].name,
                                          domain_.sourceCameras[c]
                                              ? "its region is left uncorrected"
                                              : "its seams are free (Neumann) borders"));
    }
  }

  // Regions and seams are made of whole blocks, so each block needs one camera: the one the LUT
  // gives its centre pixel.
  void findBlockOwners() {
    const int block = domain_.block;
    owner_.resize(static_cast<std::size_t>(blockCount()));
    for (int b = 0; b < blockCount(); ++b) {
      const int u = column(b) * block + block / 2;
      const int v = row(b) * block + block / 2;
      owner_[static_cast<std::size_t>(b)] =
          lut_.taps[static_cast<std::size_t>(v) * lut_.size.width + u].camera;
    }
  }

  // A field corrects one camera (its own gain and tint) and is smooth only across blocks that
  // touch: each connected set of a source camera's blocks (4-neighbours, columns wrapping) is a
  // region solved on its own.
  void findRegions() {
    std::vector<bool> visited(owner_.size(), false);
    for (int seed = 0; seed < blockCount(); ++seed) {
      if (visited[static_cast<std::size_t>(seed)] ||
          !isSource(owner_[static_cast<std::size_t>(seed)])) {
        continue;
      }
      addRegion(componentOf(grid_, owner_, seed, visited));
    }
  }

  // One connected set of a source camera's blocks becomes a region with its own PoissonSystem,
  // unless its camera is missing or it has no seam to take values from.
  void addRegion(std::vector<int> members) {
    CorrectionRegion region;
    region.source = owner_[static_cast<std::size_t>(members.front())];
    if (!isPresent(region.source)) return;
    const std::map<int, int> unknownOf = placeUnknowns(region, members);
    connectUnknowns(region, members, unknownOf);
    if (region.dirichlet.empty()) {
      domain_.notes.push_back(fmt::format(
          "a region of {} blocks of camera '{}' has no seam with a target camera: left uncorrected",
          members.size(), rig_.cameras[region.source].name));
      return;
    }
    listUnknownsOfDirichlet(region);
    addSeams(region, static_cast<std::uint32_t>(domain_.regions.size()));
    domain_.regions.push_back(std::move(region));
  }

  // The solvers see the region as pixels of its own grid (the multigrid coarsens it), so the
  // unknowns are numbered row-major in the region's frame, columns unwrapped across +-180
  // degrees. Gives each member block its unknown.
  std::map<int, int> placeUnknowns(CorrectionRegion& region, std::vector<int>& members) const {
    const int width = domain_.grid.width;
    const int x0 = firstColumn(grid_, members);
    const auto localX = [&](int b) { return (column(b) - x0 + width) % width; };
    int top = domain_.grid.height;
    for (const int b : members) top = std::min(top, row(b));
    std::ranges::sort(members, {}, [&](int b) { return std::pair{row(b), localX(b)}; });
    std::map<int, int> unknownOf;
    for (const int b : members) {
      unknownOf.emplace(b, static_cast<int>(region.blockOfUnknown.size()));
      region.blockOfUnknown.push_back(b);
      region.system.pixels.emplace_back(localX(b), row(b) - top);
      region.system.size.width = std::max(region.system.size.width, localX(b) + 1);
      region.system.size.height = std::max(region.system.size.height, row(b) - top + 1);
    }
    return unknownOf;
  }

  // The 5-point stencil's rows: a neighbour that is an unknown is a link, one across a seam with
  // a present target camera that both cameras see enough of is a Dirichlet block (made once, on
  // first meeting, so they come in row-major order), and every other border is Neumann (left out
  // of the degree).
  void connectUnknowns(CorrectionRegion& region, const std::vector<int>& members,
                       const std::map<int, int>& unknownOf) {
    std::map<int, std::uint32_t> dirichletOfBlock;
    region.dirichletBegin.push_back(0);
    for (std::size_t i = 0; i < members.size(); ++i) {
      int degree = 0;
      for (const int q : grid_.neighbours(members[i])) {
        if (q < 0) continue;
        if (const auto known = unknownOf.find(q); known != unknownOf.end()) {
          ++degree;
          if (static_cast<int>(i) < known->second)
            region.system.links.emplace_back(i, known->second);
          continue;
        }
        const std::uint8_t across = owner_[static_cast<std::size_t>(q)];
        if (across == PanoramaLut::kUnseen || isSource(across) || !isPresent(across)) {
          continue;  // Neumann
        }
        auto found = dirichletOfBlock.find(q);
        if (found == dirichletOfBlock.end()) {
          const auto dirichlet = dirichletBlock(q, across, region.source);
          if (!dirichlet) continue;  // Neumann: too little overlap
          found = dirichletOfBlock.emplace(q, static_cast<std::uint32_t>(region.dirichlet.size()))
                      .first;
          region.dirichlet.push_back(*dirichlet);
        }
        ++degree;
        region.dirichletOf.push_back(found->second);
      }
      region.system.degree.push_back(degree);
      region.dirichletBegin.push_back(static_cast<std::uint32_t>(region.dirichletOf.size()));
    }
  }

  // Block q across the seam from `source` to `target`, with the sample taps of its pixels that
  // both cameras see (a Dirichlet value is the two cameras' difference there); none when they
  // share less than kMinimumSeenShare of it.
  // Ground only: the floor's pixels as the bowl puts them, and past the floor the ground itself
  // where the pixel's ray meets it (the wall stands for that ground, but each camera sees the
  // wall's point on a different piece of it). `beyondFloor`: most samples came from past the floor.
  std::optional<DirichletBlock> dirichletBlock(int q, std::uint8_t target, std::uint8_t source) {
    const int block = domain_.block;
    const cv::Vec3d& centre = settings_.geometry.centre;
    const auto first = static_cast<std::uint32_t>(domain_.samples.size());
    const int u0 = column(q) * block;
    const int v0 = row(q) * block;
    std::size_t pastFloor = 0;
    for (int v = v0; v < v0 + block; ++v) {
      for (int u = u0; u < u0 + block; ++u) {
        const cv::Point2d pixel(u, v);
        std::optional<cv::Point2d> t;
        std::optional<cv::Point2d> s;
        if (groundOnly_) {
          const cv::Vec3d direction = settings_.geometry.direction(pixel);
          if (direction[2] > -std::sin(kHorizonMarginRad)) continue;
          cv::Vec3d point = projector_.surfacePoint(pixel);
          const bool past = point[2] > kFloorHeightM;
          if (past) point = centre + direction * (-centre[2] / direction[2]);
          t = projector_.cameraPixelOf(target, point);
          s = projector_.cameraPixelOf(source, point);
          if (t && s && past) ++pastFloor;
        } else {
          t = projector_.cameraPixel(target, pixel);
          s = projector_.cameraPixel(source, pixel);
        }
        if (!t || !s) continue;
        domain_.samples.push_back({encodeTap(*t, lut_.cameraSizes[target], target),
                                   encodeTap(*s, lut_.cameraSizes[source], source)});
      }
    }
    const std::size_t count = domain_.samples.size() - first;
    if (static_cast<double>(count) < kMinimumSeenShare * block * block) {
      domain_.samples.resize(first);
      return std::nullopt;
    }
    return DirichletBlock{q, target, first, static_cast<std::uint32_t>(domain_.samples.size()),
                          2 * pastFloor > count};
  }

  // The reverse of dirichletOf: the seam report asks what field the source's pixels next to each
  // Dirichlet block get.
  static void listUnknownsOfDirichlet(CorrectionRegion& region) {
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
  }

  // The robust statistics of poisson_correction.hpp look along each seam: its Dirichlet blocks
  // per target camera, in the order they were made, row-major, which runs along a seam (seams
  // are near-vertical in the panorama).
  void addSeams(const CorrectionRegion& region, std::uint32_t regionIndex) {
    for (std::uint32_t k = 0; k < region.dirichlet.size(); ++k) {
      const std::uint8_t target = region.dirichlet[k].target;
      auto seam = std::ranges::find_if(domain_.seams, [&](const CorrectionSeam& s) {
        return s.region == regionIndex && s.target == target;
      });
      if (seam == domain_.seams.end()) {
        domain_.seams.push_back({regionIndex, target, {}});
        seam = domain_.seams.end() - 1;
      }
      seam->blocks.push_back(k);
    }
  }

  // The fields of all regions share one array of slots (unknowns, then Dirichlet blocks), so that
  // one upsampling pass serves them all. Each block shows its own slot, and blocks within
  // kFillReach of a region the nearest one's, so the bicubic kernel has data on both sides of a
  // region's border.
  void assignFieldSlots() {
    domain_.fillFrom.assign(static_cast<std::size_t>(blockCount()), -1);
    std::deque<std::pair<int, int>> frontier;  // block, distance from a region
    for (const auto& region : domain_.regions) {
      domain_.firstUnknownSlot.push_back(static_cast<std::uint32_t>(domain_.slots));
      for (const int b : region.blockOfUnknown) {
        domain_.fillFrom[static_cast<std::size_t>(b)] = static_cast<int>(domain_.slots++);
        frontier.emplace_back(b, 0);
      }
    }
    for (const auto& region : domain_.regions) {
      domain_.firstDirichletSlot.push_back(static_cast<std::uint32_t>(domain_.slots));
      for (const auto& d : region.dirichlet) {
        domain_.fillFrom[static_cast<std::size_t>(d.block)] = static_cast<int>(domain_.slots++);
        frontier.emplace_back(d.block, 0);
      }
    }
    while (!frontier.empty()) {
      const auto [b, distance] = frontier.front();
      frontier.pop_front();
      if (distance == kFillReach) continue;
      for (const int q : grid_.neighbours(b)) {
        if (q < 0 || domain_.fillFrom[static_cast<std::size_t>(q)] >= 0) continue;
        domain_.fillFrom[static_cast<std::size_t>(q)] =
            domain_.fillFrom[static_cast<std::size_t>(b)];
        frontier.emplace_back(q, distance + 1);
      }
    }
  }

  // The field corrects only what a source camera put into a pixel: whole where a source owns it,
  // the blend weight across a seam with a target.
  void weighSources() {
    domain_.share.assign(lut_.taps.size(), 0);
    for (std::size_t i = 0; i < lut_.taps.size(); ++i) {
      if (isSource(lut_.taps[i].camera)) domain_.share[i] = 256;
    }
    for (const auto& blend : lut_.blendTaps) {
      const bool ownerIsSource = isSource(lut_.taps[blend.pixel].camera);
      if (ownerIsSource != isSource(blend.tap.camera)) {
        domain_.share[blend.pixel] =
            static_cast<std::uint16_t>(ownerIsSource ? 256 - blend.tap.weight : blend.tap.weight);
      }
    }
  }

  const Rig& rig_;
  const PanoramaSettings& settings_;
  const PanoramaLut& lut_;
  std::span<const bool> present_;
  const PanoramaProjector projector_;
  const bool groundOnly_;
  CorrectionDomain domain_;
  BlockGrid grid_;
  std::vector<std::uint8_t> owner_;  // per block: the camera that owns its centre pixel
};

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
  return DomainBuilder(rig, settings, lut, *tiling, groundSeams, present).build();
}

}  // namespace surroundd::processing
