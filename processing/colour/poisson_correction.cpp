#include "processing/colour/poisson_correction.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "common/camera_limit.hpp"
#include "common/work_pool.hpp"
#include "processing/colour/camera_gains.hpp"
#include "processing/colour/float_lanes.hpp"
#include "processing/colour/poisson_correction_state.hpp"
#include "processing/stitch/i420_picture.hpp"

namespace surroundd::processing {
namespace {

// Catmull-Rom cubic (OpenCV's INTER_CUBIC uses a sharper -0.75; -0.5 does not overshoot as much
// on the steps a correction field has at the seams).
std::array<float, 4> catmullRom(double t) {
  const double t2 = t * t;
  const double t3 = t2 * t;
  return {static_cast<float>((-t3 + 2 * t2 - t) / 2), static_cast<float>((3 * t3 - 5 * t2 + 2) / 2),
          static_cast<float>((-3 * t3 + 4 * t2 + t) / 2), static_cast<float>((t3 - t2) / 2)};
}

// Where the four bicubic taps of sub-block phase r start, relative to the block index: pixel
// centre (k * block + r + 0.5) lies at block coordinate k + (r + 0.5) / block - 0.5.
int firstTapOffset(int r, int block) {
  return static_cast<int>(std::floor((r + 0.5) / block - 0.5)) - 1;
}

// A pixel's level (a float or a vector of channels) corrected by the field's value there, clamped
// to 0..255. `weight` is the source camera's share of the pixel (`whole`: all of it).
template <CorrectionField kField, typename Level>
Level correctedLevel(Level pixel, Level value, float weight, bool whole) {
  Level corrected;
  if constexpr (kField == CorrectionField::kAdditive) {
    corrected = pixel + weight * value;
  } else {
    const Level gain = 1 + value * (1.0f / 255);
    if (whole) {
      corrected = pixel * gain;
    } else {
      // In the seam band the pixel is w * source + (1 - w) * target, with target = gain * source
      // where the field is right, so the source's part is pixel / (w + (1 - w) gain).
      corrected = pixel * gain / (weight + (1 - weight) * gain);
    }
  }
  return clampLanes(corrected, 0.0f, 255.0f);
}

// Non-negative, so adding a half and truncating rounds (lround is a libm call per value).
inline std::uint8_t roundedLevel(float level) {
  return static_cast<std::uint8_t>(level + 0.5f);  // NOLINT(bugprone-incorrect-roundings)
}
inline IntLanes roundedLevel(FloatLanes level) { return truncatedLanes(level + 0.5f); }

}  // namespace

std::string_view correctionFieldName(CorrectionField field) {
  return field == CorrectionField::kMultiplicative ? "multiplicative" : "additive";
}

PoissonColourCorrection::PoissonColourCorrection(const Rig& rig, const PanoramaSettings& panorama,
                                                 const PanoramaLut& lut,
                                                 const ColourCorrectionSettings& settings,
                                                 WorkPool& pool)
    : lut_(lut),
      pool_(pool),
      settings_(settings),
      rig_(rig),
      panorama_(panorama),
      missingSets_(rig.cameras.size(), 0),
      meters_(static_cast<std::size_t>(pool.threads()) * 4,
              SeamBlockMeter(static_cast<std::size_t>(
                  std::lround(1 / settings.scale * (1 / settings.scale))))),
      window_(2 * kSeamHalfWindow + 1) {
  activeCameras_ = (1U << rig.cameras.size()) - 1;
  full_ = &configurationFor(activeCameras_);
  active_ = full_;
  const CorrectionDomain& domain = full_->domain;
  if (settings.balance) {
    std::vector<std::string> names;
    for (const auto& camera : rig.cameras) names.push_back(camera.name);
    balance_ = std::make_unique<ColourBalance>(std::move(names), settings.minGain, settings.maxGain,
                                               settings.balanceSmoothing,
                                               settings.balanceReference);
    pairRatios_.resize(domain.seams.size());
    present_.resize(rig.cameras.size());
  }
  fieldStorage_.assign(static_cast<std::size_t>(domain.grid.area()) * 3 + 1, 0.0F);
  field_ = cv::Mat(domain.grid, CV_32FC3, fieldStorage_.data());
  for (int r = 0; r < domain.block; ++r) {
    const double t = (r + 0.5) / domain.block - 0.5;
    phaseWeights_.push_back(catmullRom(t - std::floor(t)));
  }
  // One float past the last block: the vector apply reads four floats for a block's three channels.
  rowBuffers_.assign(
      static_cast<std::size_t>(pool.threads()) * 4,
      std::vector<float>(static_cast<std::size_t>(domain.grid.width + 2 * kPad) * 3 + 1));
  for (int u = 0; u < lut.size.width; ++u) {
    columnTap_.push_back(u / domain.block + firstTapOffset(u % domain.block, domain.block));
  }
  for (int v = 0; v < lut.size.height; ++v) {
    const auto* share = domain.share.data() + static_cast<std::size_t>(v) * lut.size.width;
    rowHasShare_.push_back(
        std::any_of(share, share + lut.size.width, [](std::uint16_t w) { return w != 0; }));
  }
}

PoissonColourCorrection::~PoissonColourCorrection() = default;

const std::vector<std::string>& PoissonColourCorrection::notes() const {
  return full_->domain.notes;
}

const CorrectionDomain& PoissonColourCorrection::domain() const { return active_->domain; }

ColourField PoissonColourCorrection::asColourField() const {
  const CorrectionDomain& shape = domain();
  return {&field_, shape.share, shape.block, settings_.field == CorrectionField::kAdditive,
          cameraGains()};
}

// Which cameras are present is a bitmask (configurationFor's key); the rig's LUT holds at most
// kMaxCameras (buildPanoramaLut), so every camera has its bit.
static_assert(kMaxCameras <= 32, "a std::uint32_t camera bitmask holds every camera");

PoissonColourCorrection::Configuration& PoissonColourCorrection::configurationFor(
    std::uint32_t presentCameras) {
  auto& configuration = configurations_[presentCameras];
  if (configuration) return *configuration;
  std::array<bool, kMaxCameras> present{};
  for (std::size_t c = 0; c < rig_.cameras.size(); ++c) present[c] = (presentCameras >> c) & 1U;
  configuration = std::make_unique<Configuration>();
  configuration->domain =
      buildCorrectionDomain(rig_, panorama_, lut_, settings_.scale, settings_.groundSeams,
                            std::span(present.data(), rig_.cameras.size()));
  for (const auto& region : configuration->domain.regions) {
    RegionState state;
    state.solver = makePoissonSolver(settings_.solver, region.system, settings_.tolerance);
    const std::size_t blocks = region.dirichlet.size();
    state.levels.resize(blocks);
    state.measuredValid.assign(blocks, 0);
    state.filteredValid.assign(blocks, 0);
    state.measured.assign(blocks * 3, 0.0f);
    state.filtered.assign(blocks * 3, 0.0f);
    state.seamValue.assign(blocks * 3, 0.0f);
    state.dirichlet.assign(blocks * 3, 0.0f);
    state.rhs.assign(region.system.unknowns() * 3, 0.0f);
    state.solution.assign(region.system.unknowns() * 3, 0.0f);
    state.otherSolution.assign(region.system.unknowns() * 3, 0.0f);
    configuration->regions.push_back(std::move(state));
  }
  configuration->slots.assign(configuration->domain.slots * 3, 0.0f);
  const std::size_t seams = configuration->domain.seams.size();
  configuration->saidClamped.assign(seams, 0);
  configuration->saidSparse.assign(seams, 0);
  configuration->saidDropped.assign(seams, 0);
  resolve_.resize(std::max(resolve_.size(), configuration->domain.regions.size()));
  for (const auto& seam : configuration->domain.seams) {
    stepScratch_.resize(std::max(stepScratch_.size(), 4 * seam.blocks.size()));
  }
  return *configuration;
}

std::string PoissonColourCorrection::solverNames() const {
  std::string names;
  for (const auto& region : active_->regions) {
    names += fmt::format("{}{}", names.empty() ? "" : ", ", region.solver->name());
  }
  return names;
}

void PoissonColourCorrection::followLostCameras(std::span<const cv::Mat> frames) {
  changes_.clear();
  std::uint32_t present = 0;
  for (std::size_t c = 0; c < missingSets_.size(); ++c) {
    missingSets_[c] = frames[c].empty() ? missingSets_[c] + 1 : 0;
    if (missingSets_[c] < kLostAfterSets) present |= 1U << c;
  }
  if (present == activeCameras_) return;
  const bool firstTime = !configurations_.contains(present);
  const auto start = std::chrono::steady_clock::now();
  active_ = &configurationFor(present);
  activeCameras_ = present;
  if (!firstTime) return;
  // What the start-up domain already said is not news.
  for (const auto& note : active_->domain.notes) {
    if (std::ranges::find(full_->domain.notes, note) == full_->domain.notes.end()) {
      changes_.push_back(note);
    }
  }
  changes_.push_back(fmt::format(
      "colour correction domain rebuilt for the cameras present in {:.0f} ms: {} region(s), "
      "solver {}",
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count(),
      active_->domain.regions.size(), solverNames()));
}

void PoissonColourCorrection::solveRegions(std::span<const std::uint8_t> which) {
  Configuration& active = *active_;
  pool_.parallelFor(
      static_cast<int>(active.regions.size()),
      [&](int first, int last) {
        for (int r = first; r < last; ++r) {
          if (!which.empty() && which[static_cast<std::size_t>(r)] == 0) continue;
          const CorrectionRegion& region = active.domain.regions[static_cast<std::size_t>(r)];
          RegionState& state = active.regions[static_cast<std::size_t>(r)];
          for (std::size_t i = 0; i < region.system.unknowns(); ++i) {
            float sum[3] = {0, 0, 0};
            for (auto k = region.dirichletBegin[i]; k < region.dirichletBegin[i + 1]; ++k) {
              for (int c = 0; c < 3; ++c) sum[c] += state.dirichlet[region.dirichletOf[k] * 3 + c];
            }
            for (int c = 0; c < 3; ++c) state.rhs[i * 3 + c] = sum[c];
          }
          state.iterations += state.solver->solve(state.rhs, state.solution).iterations;
        }
      },
      static_cast<int>(active.regions.size()));
}

int PoissonColourCorrection::update(std::span<const cv::Mat> frames, PixelFormat format) {
  followLostCameras(frames);
  gatherSeams(frames, format);
  Configuration& active = *active_;
  for (auto& state : active.regions) {
    state.iterations = 0;
    // Solved twice last frame: `solution` holds the field without the dropped data, and the
    // field with all of it, the warm start of the first solve, waits in `otherSolution`.
    if (state.solvedTwice) std::swap(state.solution, state.otherSolution);
  }
  solveRegions({});
  const bool dropped = dropWorseningSeams();
  for (std::size_t r = 0; r < active.regions.size(); ++r) {
    RegionState& state = active.regions[r];
    const bool twice = dropped && resolve_[r] != 0;
    if (twice) {
      // The second solve starts from last frame's second solve, if there was one.
      if (state.solvedTwice) {
        std::swap(state.solution, state.otherSolution);
      } else {
        state.otherSolution = state.solution;  // same size: no allocation
      }
    }
    state.solvedTwice = twice;
  }
  if (dropped) solveRegions(std::span(resolve_.data(), active.regions.size()));

  int iterations = 0;
  for (std::size_t r = 0; r < active.regions.size(); ++r) {
    const RegionState& state = active.regions[r];
    std::copy(
        state.solution.begin(), state.solution.end(),
        active.slots.begin() + static_cast<std::ptrdiff_t>(active.domain.firstUnknownSlot[r]) * 3);
    std::copy(state.dirichlet.begin(), state.dirichlet.end(),
              active.slots.begin() +
                  static_cast<std::ptrdiff_t>(active.domain.firstDirichletSlot[r]) * 3);
    iterations += state.iterations;
  }
  if (settings_.field == CorrectionField::kMultiplicative) {
    // Log-gains to the levels they add at 255, in place (the slots are refilled every frame).
    cv::Mat values(1, static_cast<int>(active.slots.size()), CV_32F, active.slots.data());
    cv::exp(values, values);
    values.convertTo(values, CV_32F, 255, -255);
  }
  auto* field = field_.ptr<float>();
  for (std::size_t b = 0; b < active.domain.fillFrom.size(); ++b) {
    const int slot = active.domain.fillFrom[b];
    for (int c = 0; c < 3; ++c) {
      field[b * 3 + c] = slot < 0 ? 0.0f : active.slots[static_cast<std::size_t>(slot) * 3 + c];
    }
  }
  return iterations;
}

template <typename Instance>
auto PoissonColourCorrection::kernelFor(KernelPath path, Instance instance) const {
  if (!kernelPathBuilt(path)) {
    throw std::invalid_argument(
        fmt::format("colour correction: this build has no {} kernels", kernelPathName(path)));
  }
  constexpr auto kMultiplicative = CorrectionField::kMultiplicative;
  constexpr auto kAdditive = CorrectionField::kAdditive;
  const bool multiplicative = settings_.field == kMultiplicative;
  if (path == KernelPath::kPortable) {
    return multiplicative ? instance.template operator()<kMultiplicative, KernelPath::kPortable>()
                          : instance.template operator()<kAdditive, KernelPath::kPortable>();
  }
  return multiplicative ? instance.template operator()<kMultiplicative, kNativeKernels>()
                        : instance.template operator()<kAdditive, kNativeKernels>();
}

void PoissonColourCorrection::apply(cv::Mat& panorama, KernelPath path) {
  if (balance_) applyCameraGains(panorama, lut_, balance_->gains(), pool_);
  const auto rows = kernelFor(path, []<CorrectionField kField, KernelPath kPath>() {
    return &PoissonColourCorrection::applyRows<kField, kPath>;
  });
  const int chunks = static_cast<int>(rowBuffers_.size());
  pool_.parallelFor(
      chunks,
      [&](int firstChunk, int lastChunk) {
        for (int chunk = firstChunk; chunk < lastChunk; ++chunk) {
          const int height = lut_.size.height;
          const int first = height * chunk / chunks;
          const int last = height * (chunk + 1) / chunks;
          auto& buffer = rowBuffers_[static_cast<std::size_t>(chunk)];
          (this->*rows)(first, last, panorama, buffer);
        }
      },
      chunks);
}

template <CorrectionField kField, KernelPath kPath>
void PoissonColourCorrection::applyRows(int first, int last, cv::Mat& panorama,
                                        std::vector<float>& columnBuffer) const {
  const CorrectionDomain& domain = full_->domain;  // its grid and shares are every domain's
  const int block = domain.block;
  const int gridWidth = domain.grid.width;
  const int gridHeight = domain.grid.height;
  const int width = lut_.size.width;
  // The row at block resolution, with kPad wrapped-around blocks on each side so that the
  // horizontal taps need no modulo.
  float* column = columnBuffer.data() + static_cast<std::size_t>(kPad) * 3;
  for (int v = first; v < last; ++v) {
    const std::uint16_t* share = domain.share.data() + static_cast<std::size_t>(v) * width;
    if (!rowHasShare_[static_cast<std::size_t>(v)]) continue;
    // Vertical pass: the field interpolated to this row.
    const auto& wy = phaseWeights_[static_cast<std::size_t>(v % block)];
    const int firstRow = v / block + firstTapOffset(v % block, block);
    const float* rows[4];
    for (int j = 0; j < 4; ++j) {
      rows[j] = field_.ptr<float>(std::clamp(firstRow + j, 0, gridHeight - 1));
    }
    for (int x = 0; x < gridWidth * 3; ++x) {
      column[x] = wy[0] * rows[0][x] + wy[1] * rows[1][x] + wy[2] * rows[2][x] + wy[3] * rows[3][x];
    }
    for (int x = 0; x < kPad * 3; ++x) {
      column[-kPad * 3 + x] = column[(gridWidth - kPad) * 3 + x];
      column[gridWidth * 3 + x] = column[x];
    }
    // Horizontal pass where a source camera contributes: the three channels one at a time, or as
    // three lanes of one vector operation (SSE2, NEON: float_lanes.hpp), with the same roundings.
    auto* out = panorama.ptr<std::uint8_t>(v);
    for (int u = 0; u < width; ++u) {
      if (share[u] == 0) continue;
      const auto& wx = phaseWeights_[static_cast<std::size_t>(u % block)];
      const float* tap =
          column + static_cast<std::ptrdiff_t>(columnTap_[static_cast<std::size_t>(u)]) * 3;
      const float weight = share[u] * (1.0f / 256);
      const bool whole = share[u] == 256;
      std::uint8_t* pixel = out + static_cast<std::size_t>(u) * 3;
      if constexpr (kPath == KernelPath::kPortable) {
        for (int c = 0; c < 3; ++c) {
          const float value =
              wx[0] * tap[c] + wx[1] * tap[3 + c] + wx[2] * tap[6 + c] + wx[3] * tap[9 + c];
          pixel[c] = roundedLevel(
              correctedLevel<kField>(static_cast<float>(pixel[c]), value, weight, whole));
        }
      } else {
        // Lane 3 reads the next block's first channel (the buffer has a float to spare at its
        // end) and is dropped.
        const FloatLanes value = wx[0] * loadLanes(tap) + wx[1] * loadLanes(tap + 3) +
                                 wx[2] * loadLanes(tap + 6) + wx[3] * loadLanes(tap + 9);
        const FloatLanes level = {static_cast<float>(pixel[0]), static_cast<float>(pixel[1]),
                                  static_cast<float>(pixel[2]), 0};
        const IntLanes rounded = roundedLevel(correctedLevel<kField>(level, value, weight, whole));
        for (int c = 0; c < 3; ++c) pixel[c] = static_cast<std::uint8_t>(rounded[c]);
      }
    }
  }
}

PoissonColourCorrection::ViewSamples PoissonColourCorrection::viewSamples(
    const cv::Mat& panoramaPositions) const {
  if (panoramaPositions.type() != CV_32FC2) {
    throw std::invalid_argument("view samples: panorama positions must be CV_32FC2");
  }
  const CorrectionDomain& domain = full_->domain;
  const cv::Size grid = domain.grid;
  const cv::Size panorama = lut_.size;
  ViewSamples samples;
  samples.size = panoramaPositions.size();
  samples.taps.resize(panoramaPositions.total());
  for (int v = 0; v < samples.size.height; ++v) {
    const auto* positions = panoramaPositions.ptr<cv::Point2f>(v);
    for (int u = 0; u < samples.size.width; ++u) {
      const cv::Point2f at = positions[u];
      if (!std::isfinite(at.x) || !std::isfinite(at.y)) continue;
      ViewTap& tap = samples.taps[static_cast<std::size_t>(v) * samples.size.width + u];
      // Block centres, in the grid's coordinates, as apply() places them.
      const double gx = (at.x + 0.5) / domain.block - 0.5;
      const double gy = (at.y + 0.5) / domain.block - 0.5;
      const double left = std::floor(gx);
      double top = std::floor(gy);
      tap.fx = static_cast<float>(gx - left);
      tap.fy = static_cast<float>(gy - top);
      if (top < 0 || top >= grid.height - 1) {
        top = std::clamp(top, 0.0, grid.height - 1.0);
        tap.fy = 0;
      }
      const int column = ((static_cast<int>(left) % grid.width) + grid.width) % grid.width;
      const int row = static_cast<int>(top);
      tap.block = static_cast<std::uint32_t>(row * grid.width + column);
      tap.right = static_cast<std::int16_t>(column == grid.width - 1 ? 1 - grid.width : 1);
      tap.down = static_cast<std::int16_t>(row == grid.height - 1 ? 0 : grid.width);
      const int pu = ((static_cast<int>(std::lround(at.x)) % panorama.width) + panorama.width) %
                     panorama.width;
      const int pv = std::clamp(static_cast<int>(std::lround(at.y)), 0, panorama.height - 1);
      tap.share = domain.share[static_cast<std::size_t>(pv) * panorama.width + pu];
    }
  }
  return samples;
}

PoissonColourCorrection::ViewRows PoissonColourCorrection::viewRowsFor(const ViewSamples& samples,
                                                                       const cv::Mat& picture,
                                                                       KernelPath path) const {
  if (picture.type() != CV_8UC3 || picture.size() != samples.size) {
    throw std::invalid_argument(
        fmt::format("colour correction: expected an 8-bit BGR picture of {}x{}", samples.size.width,
                    samples.size.height));
  }
  return kernelFor(path, []<CorrectionField kField, KernelPath kPath>() {
    return &PoissonColourCorrection::applyAtRows<kField, kPath>;
  });
}

void PoissonColourCorrection::applyAt(const ViewSamples& samples, cv::Mat& picture,
                                      KernelPath path) {
  const ViewRows rows = viewRowsFor(samples, picture, path);
  pool_.parallelFor(
      samples.size.height,
      [&](int first, int last) { (this->*rows)(first, last, samples, picture); },
      pool_.threads() * 4);
}

void PoissonColourCorrection::applyAt(const ViewSamples& samples, cv::Mat& picture, cv::Mat& i420,
                                      KernelPath path) {
  const ViewRows rows = viewRowsFor(samples, picture, path);
  if (picture.cols % 2 != 0 || picture.rows % 2 != 0) {
    throw std::invalid_argument("colour correction: an I420 picture needs even sides");
  }
  i420.create(i420HeldSize(picture.size()), CV_8UC1);
  pool_.parallelFor(
      samples.size.height / 2,
      [&](int first, int last) {
        for (int pair = first; pair < last; ++pair) {
          (this->*rows)(2 * pair, 2 * pair + 2, samples, picture);
          bgrRowsToI420(picture, 2 * pair, 2 * pair + 2, i420, path);
        }
      },
      pool_.threads() * 4);
}

template <CorrectionField kField, KernelPath kPath>
void PoissonColourCorrection::applyAtRows(int first, int last, const ViewSamples& samples,
                                          cv::Mat& picture) const {
  const auto* field = field_.ptr<float>();
  for (int v = first; v < last; ++v) {
    const ViewTap* taps = samples.taps.data() + static_cast<std::size_t>(v) * samples.size.width;
    auto* pixel = picture.ptr<std::uint8_t>(v);
    for (int u = 0; u < samples.size.width; ++u, pixel += 3) {
      const ViewTap& tap = taps[u];
      if (tap.share == 0) continue;
      const float* topLeft = field + static_cast<std::size_t>(tap.block) * 3;
      const float* topRight = topLeft + static_cast<std::ptrdiff_t>(tap.right) * 3;
      const float* bottomLeft = topLeft + static_cast<std::ptrdiff_t>(tap.down) * 3;
      const float* bottomRight = bottomLeft + static_cast<std::ptrdiff_t>(tap.right) * 3;
      const float weight = tap.share * (1.0f / 256);
      const bool whole = tap.share == 256;
      if constexpr (kPath == KernelPath::kPortable) {
        for (int c = 0; c < 3; ++c) {
          const float upper = topLeft[c] + tap.fx * (topRight[c] - topLeft[c]);
          const float lower = bottomLeft[c] + tap.fx * (bottomRight[c] - bottomLeft[c]);
          const float value = upper + tap.fy * (lower - upper);
          pixel[c] = roundedLevel(
              correctedLevel<kField>(static_cast<float>(pixel[c]), value, weight, whole));
        }
      } else {
        // The same operations on the three channels as lanes of one vector; lane 3 reads the next
        // block's first channel (fieldStorage_ has a float to spare at its end) and is dropped.
        const FloatLanes topLeftLanes = loadLanes(topLeft);
        const FloatLanes bottomLeftLanes = loadLanes(bottomLeft);
        const FloatLanes upper = topLeftLanes + tap.fx * (loadLanes(topRight) - topLeftLanes);
        const FloatLanes lower =
            bottomLeftLanes + tap.fx * (loadLanes(bottomRight) - bottomLeftLanes);
        const FloatLanes value = upper + tap.fy * (lower - upper);
        const FloatLanes level = {static_cast<float>(pixel[0]), static_cast<float>(pixel[1]),
                                  static_cast<float>(pixel[2]), 0};
        const IntLanes rounded = roundedLevel(correctedLevel<kField>(level, value, weight, whole));
        for (int c = 0; c < 3; ++c) pixel[c] = static_cast<std::uint8_t>(rounded[c]);
      }
    }
  }
}

}  // namespace surroundd::processing
