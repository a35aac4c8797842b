#include "processing/poisson_correction.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "common/work_pool.hpp"

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

// A seam block black in one camera has no ratio; half a level keeps its logarithm finite.
constexpr float kDarkestMean = 0.5f;
// Half-width of the running median along a seam, in blocks: wide enough to outvote an object or a
// parallax streak a few blocks long, narrow enough to follow vignetting along the seam.
constexpr int kSeamHalfWindow = 3;
float medianOf(float* values, std::size_t count) {
  std::nth_element(values, values + count / 2, values + count);
  return values[count / 2];
}

// "Worse" is worse by more than 8-bit rounding and sensor noise move a block's step: on cameras
// that already agree the seams would otherwise drop in and out with the noise.
constexpr double kWorseLevels = 0.5;
constexpr double kWorseShare = 0.05;
// The rule is also kept for each stretch of this many blocks along a seam, which needs at least
// kMinimumSegmentBlocks of them measured.
constexpr std::size_t kSegmentBlocks = 16;
constexpr std::size_t kMinimumSegmentBlocks = 4;

// A seam needs this share of its blocks measured to be matched at all; with fewer it keeps gain 1.
constexpr double kMinimumMeasuredShare = 0.25;

}  // namespace

std::string_view correctionFieldName(CorrectionField field) {
  return field == CorrectionField::kMultiplicative ? "multiplicative" : "additive";
}

struct PoissonColourCorrection::RegionState {
  std::unique_ptr<PoissonSolver> solver;
  // Per Dirichlet block: this frame's levels, and 3 values each of log(target / source), or
  // target - source in levels (additive): as measured, filtered along the seam and bounded, and
  // smoothed over time. `dirichlet` is what is solved: the smoothed data, 0 on dropped seams.
  std::vector<SeamBlockLevels> levels;
  std::vector<std::uint8_t> measuredValid, filteredValid;
  std::vector<float> measured, filtered, seamValue;
  std::vector<float> dirichlet;
  std::vector<float> rhs;
  std::vector<float> solution;  // 3 per unknown; the warm start of the next frame
  int iterations = 0;
};

struct PoissonColourCorrection::Configuration {
  CorrectionDomain domain;
  std::vector<RegionState> regions;
  std::vector<float> slots;  // 3 values per field slot
  bool firstFrame = true;
  // Per seam: whether its clamp, its lack of data and its dropping have been said.
  std::vector<std::uint8_t> saidClamped, saidSparse, saidDropped;
};

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
      meter_(static_cast<std::size_t>(std::lround(1 / settings.scale * (1 / settings.scale)))),
      window_(2 * kSeamHalfWindow + 1) {
  activeCameras_ = (1U << rig.cameras.size()) - 1;
  full_ = &configurationFor(activeCameras_);
  active_ = full_;
  const CorrectionDomain& domain = full_->domain;
  field_.create(domain.grid, CV_32FC3);
  field_.setTo(cv::Scalar::all(0));
  for (int r = 0; r < domain.block; ++r) {
    const double t = (r + 0.5) / domain.block - 0.5;
    phaseWeights_.push_back(catmullRom(t - std::floor(t)));
  }
  rowBuffers_.assign(
      static_cast<std::size_t>(pool.threads()) * 4,
      std::vector<float>(static_cast<std::size_t>(domain.grid.width + 2 * kPad) * 3));
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

PoissonColourCorrection::Configuration& PoissonColourCorrection::configurationFor(
    std::uint32_t presentCameras) {
  auto& configuration = configurations_[presentCameras];
  if (configuration) return *configuration;
  std::array<bool, 32> present{};
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

void PoissonColourCorrection::noteOnce(std::vector<std::uint8_t>& said, std::size_t seam,
                                       std::string note) {
  if (said[seam] != 0) return;
  said[seam] = 1;
  changes_.push_back(std::move(note));
}

void PoissonColourCorrection::gatherSeams(std::span<const cv::Mat> frames) {
  Configuration& active = *active_;
  const float keep = active.firstFrame ? 0.0f : static_cast<float>(settings_.temporalSmoothing);
  const bool multiplicative = settings_.field == CorrectionField::kMultiplicative;
  for (std::size_t r = 0; r < active.regions.size(); ++r) {
    const CorrectionRegion& region = active.domain.regions[r];
    RegionState& state = active.regions[r];
    const cv::Mat& source = frames[region.source];
    for (std::size_t k = 0; k < region.dirichlet.size(); ++k) {
      const DirichletBlock& d = region.dirichlet[k];
      const cv::Mat& target = frames[d.target];
      state.measuredValid[k] = 0;
      if (source.empty() || target.empty()) continue;
      const SeamBlockLevels levels = meter_.measure(active.domain, d, target, source);
      state.levels[k] = levels;
      state.measuredValid[k] = levels.valid ? 1 : 0;
      for (int c = 0; c < 3; ++c) {
        state.measured[k * 3 + c] = multiplicative
                                        ? std::log(std::max(levels.target[c], kDarkestMean) /
                                                   std::max(levels.source[c], kDarkestMean))
                                        : levels.target[c] - levels.source[c];
      }
    }
  }

  seamReports_.resize(active.domain.seams.size());
  const auto logMin = static_cast<float>(std::log(settings_.minGain));
  const auto logMax = static_cast<float>(std::log(settings_.maxGain));
  for (std::size_t i = 0; i < active.domain.seams.size(); ++i) {
    const CorrectionSeam& seam = active.domain.seams[i];
    const CorrectionRegion& region = active.domain.regions[seam.region];
    RegionState& state = active.regions[seam.region];
    SeamReport& report = seamReports_[i];
    report = {region.source, seam.target, static_cast<int>(seam.blocks.size())};
    // A camera missing from this set: the seam holds its last values.
    if (frames[region.source].empty() || frames[seam.target].empty()) continue;
    medianAlongSeam(seam.blocks, state.measured, state.measuredValid, kSeamHalfWindow, window_,
                    state.filtered, state.filteredValid);
    cv::Vec3f sourceLevel(0, 0, 0);
    for (const auto k : seam.blocks) {
      if (state.measuredValid[k] == 0) continue;
      ++report.validBlocks;
      sourceLevel += state.levels[k].source;
    }
    if (report.validBlocks > 0) sourceLevel /= static_cast<float>(report.validBlocks);
    const bool sparse = report.validBlocks < kMinimumMeasuredShare * report.blocks;
    if (sparse) {
      noteOnce(active.saidSparse, i,
               fmt::format("seam {}/{}: {} of {} blocks measurable (too little ground both cameras "
                           "see unmasked): kept at gain 1",
                           rig_.cameras[region.source].name, rig_.cameras[seam.target].name,
                           report.validBlocks, report.blocks));
    }
    float furthest = 0;
    for (const auto k : seam.blocks) {
      bool clamped = false;
      for (int c = 0; c < 3; ++c) {
        float value = sparse || state.filteredValid[k] == 0 ? 0.0f : state.filtered[k * 3 + c];
        const float low =
            multiplicative ? logMin : static_cast<float>(settings_.minGain - 1) * sourceLevel[c];
        const float high =
            multiplicative ? logMax : static_cast<float>(settings_.maxGain - 1) * sourceLevel[c];
        if (value < low || value > high) {
          clamped = true;
          furthest = std::max(
              furthest, std::abs(multiplicative ? value : value / std::max(sourceLevel[c], 1.0f)));
          value = std::clamp(value, low, high);
        }
        float& smoothed = state.seamValue[k * 3 + c];
        smoothed = keep * smoothed + (1 - keep) * value;
        state.dirichlet[k * 3 + c] = smoothed;
      }
      report.clampedBlocks += clamped ? 1 : 0;
    }
    if (report.clampedBlocks > 0) {
      noteOnce(active.saidClamped, i,
               fmt::format("seam {}/{}: the correction asked for more than gains {:g}..{:g} on {} "
                           "of {} blocks (up to x{:.2f}): clamped",
                           rig_.cameras[region.source].name, rig_.cameras[seam.target].name,
                           settings_.minGain, settings_.maxGain, report.clampedBlocks,
                           report.blocks, multiplicative ? std::exp(furthest) : 1 + furthest));
    }
  }
  active.firstFrame = false;
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

bool PoissonColourCorrection::dropWorseningSeams() {
  Configuration& active = *active_;
  const bool multiplicative = settings_.field == CorrectionField::kMultiplicative;
  std::fill(resolve_.begin(), resolve_.end(), 0);
  bool dropped = false;
  // Per block of a seam (NaN where not measured): its step without and with the field; then room
  // to take medians in.
  const std::size_t room = stepScratch_.size() / 4;
  float* uncorrected = stepScratch_.data();
  float* corrected = uncorrected + room;
  float* pickBefore = corrected + room;
  float* pickAfter = pickBefore + room;
  // The median steps of positions [first, last) of the seam; false with too few measured.
  const auto steps = [&](std::size_t first, std::size_t last, double& before, double& after) {
    std::size_t count = 0;
    for (std::size_t j = first; j < last; ++j) {
      if (std::isnan(uncorrected[j])) continue;
      pickBefore[count] = uncorrected[j];
      pickAfter[count++] = corrected[j];
    }
    if (count < kMinimumSegmentBlocks) return false;
    before = medianOf(pickBefore, count);
    after = medianOf(pickAfter, count);
    return true;
  };
  const auto worse = [](double before, double after) {
    return after > before * (1 + kWorseShare) + kWorseLevels;
  };
  for (std::size_t i = 0; i < active.domain.seams.size(); ++i) {
    const CorrectionSeam& seam = active.domain.seams[i];
    const CorrectionRegion& region = active.domain.regions[seam.region];
    RegionState& state = active.regions[seam.region];
    SeamReport& report = seamReports_[i];
    for (std::size_t j = 0; j < seam.blocks.size(); ++j) {
      const auto k = seam.blocks[j];
      const auto first = region.unknownsBegin[k];
      const auto count = region.unknownsBegin[k + 1] - first;
      uncorrected[j] = corrected[j] = std::numeric_limits<float>::quiet_NaN();
      if (state.measuredValid[k] == 0 || count == 0) continue;
      const SeamBlockLevels& levels = state.levels[k];
      float before = 0;
      float after = 0;
      for (int c = 0; c < 3; ++c) {
        // What the source's pixels next to the seam get: the field at the unknowns beside it.
        float field = 0;
        for (auto u = first; u < first + count; ++u) {
          field += state.solution[region.unknownsOf[u] * 3 + c];
        }
        field /= static_cast<float>(count);
        const float source =
            multiplicative ? levels.source[c] * std::exp(field) : levels.source[c] + field;
        before += std::abs(levels.target[c] - levels.source[c]) / 3;
        after += std::abs(levels.target[c] - std::clamp(source, 0.0f, 255.0f)) / 3;
      }
      uncorrected[j] = before;
      corrected[j] = after;
    }
    if (report.validBlocks < kMinimumMeasuredShare * report.blocks ||
        !steps(0, seam.blocks.size(), report.stepUncorrected, report.stepCorrected)) {
      continue;
    }
    // The whole seam's typical block, then each stretch of it: near ground and far ground differ
    // (vignetting, light), and a field that helps one may hurt the other.
    const bool whole = worse(report.stepUncorrected, report.stepCorrected);
    for (std::size_t first = 0; first < seam.blocks.size(); first += kSegmentBlocks) {
      const std::size_t last = std::min(first + kSegmentBlocks, seam.blocks.size());
      double before = 0;
      double after = 0;
      if (!whole && (!steps(first, last, before, after) || !worse(before, after))) continue;
      report.droppedBlocks += static_cast<int>(last - first);
      for (std::size_t j = first; j < last; ++j) {
        std::fill_n(state.dirichlet.begin() + static_cast<std::ptrdiff_t>(seam.blocks[j]) * 3, 3,
                    0.0f);
      }
    }
    if (report.droppedBlocks == 0) continue;
    noteOnce(active.saidDropped, i,
             fmt::format("seam {}/{}: correcting {} of its {} blocks would make their step worse "
                         "(the seam's: {:.1f} against {:.1f} levels uncorrected): their data is "
                         "dropped (gain 1 there)",
                         rig_.cameras[region.source].name, rig_.cameras[seam.target].name,
                         report.droppedBlocks, report.blocks, report.stepCorrected,
                         report.stepUncorrected));
    report.dropped = whole;
    if (whole) report.stepCorrected = report.stepUncorrected;
    dropped = true;
    resolve_[seam.region] = 1;
  }
  return dropped;
}

int PoissonColourCorrection::update(std::span<const cv::Mat> frames) {
  followLostCameras(frames);
  gatherSeams(frames);
  Configuration& active = *active_;
  for (auto& state : active.regions) state.iterations = 0;
  solveRegions({});
  if (dropWorseningSeams()) {
    solveRegions(std::span(resolve_.data(), active.regions.size()));
  }

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

void PoissonColourCorrection::apply(cv::Mat& panorama) {
  const int chunks = static_cast<int>(rowBuffers_.size());
  pool_.parallelFor(
      chunks,
      [&](int firstChunk, int lastChunk) {
        for (int chunk = firstChunk; chunk < lastChunk; ++chunk) {
          const int height = lut_.size.height;
          const int first = height * chunk / chunks;
          const int last = height * (chunk + 1) / chunks;
          auto& buffer = rowBuffers_[static_cast<std::size_t>(chunk)];
          if (settings_.field == CorrectionField::kMultiplicative) {
            applyRows<CorrectionField::kMultiplicative>(first, last, panorama, buffer);
          } else {
            applyRows<CorrectionField::kAdditive>(first, last, panorama, buffer);
          }
        }
      },
      chunks);
}

template <CorrectionField kField>
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
    // Horizontal pass where a source camera contributes.
    auto* out = panorama.ptr<std::uint8_t>(v);
    for (int u = 0; u < width; ++u) {
      if (share[u] == 0) continue;
      const auto& wx = phaseWeights_[static_cast<std::size_t>(u % block)];
      const float* tap =
          column + static_cast<std::ptrdiff_t>(columnTap_[static_cast<std::size_t>(u)]) * 3;
      const float weight = share[u] * (1.0f / 256);
      std::uint8_t* pixel = out + static_cast<std::size_t>(u) * 3;
      for (int c = 0; c < 3; ++c) {
        const float value =
            wx[0] * tap[c] + wx[1] * tap[3 + c] + wx[2] * tap[6 + c] + wx[3] * tap[9 + c];
        float corrected = 0;
        if constexpr (kField == CorrectionField::kAdditive) {
          corrected = pixel[c] + weight * value;
        } else {
          const float gain = 1 + value * (1.0f / 255);
          if (share[u] == 256) {
            corrected = pixel[c] * gain;
          } else {
            // In the seam band the pixel is w * source + (1 - w) * target, with target = gain *
            // source where the field is right, so the source's part is pixel / (w + (1 - w) gain).
            corrected = pixel[c] * gain / (weight + (1 - weight) * gain);
          }
        }
        corrected = std::clamp(corrected, 0.0f, 255.0f);
        // Non-negative, so adding a half and truncating rounds (lround is a libm call per value).
        pixel[c] =
            static_cast<std::uint8_t>(corrected + 0.5f);  // NOLINT(bugprone-incorrect-roundings)
      }
    }
  }
}

}  // namespace surroundd::processing
