// The per-frame seam data of Poisson colour correction and the rule that correction never makes a
// seam worse than none (poisson_correction.hpp says what they do and why).

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "common/work_pool.hpp"
#include "processing/colour/poisson_correction_state.hpp"

namespace surroundd::processing {
namespace {

// A seam block black in one camera has no ratio; half a level keeps its logarithm finite.
constexpr float kDarkestMean = 0.5f;
float medianOf(float* values, std::size_t count) {
  std::nth_element(values, values + count / 2, values + count);
  return values[count / 2];
}

// What the field is solved for at a seam block, channel c: log(target / source), or the levels'
// difference for an additive field.
float seamValue(const SeamBlockLevels& levels, int c, bool multiplicative) {
  return multiplicative ? std::log(std::max(levels.target[c], kDarkestMean) /
                                   std::max(levels.source[c], kDarkestMean))
                        : levels.target[c] - levels.source[c];
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
// The far ground (seam blocks past the bowl's floor) gets one value per seam, the median of its
// measured blocks, when it has at least this many.
constexpr std::size_t kMinimumFarBlocks = 4;
// ... and when its median is within this of the near ground's (each channel): a factor of 1.5
// (log), or 40 levels (additive). Light falling off towards a lens's edge differs by less.
constexpr float kFarBandLogSpread = 0.405465f;  // log(1.5)
constexpr float kFarBandLevelSpread = 40.0f;

}  // namespace

void PoissonColourCorrection::noteOnce(std::vector<std::uint8_t>& said, std::size_t seam,
                                       std::string note) {
  if (said[seam] != 0) return;
  said[seam] = 1;
  changes_.push_back(std::move(note));
}

void PoissonColourCorrection::farGroundAsOneBand(const CorrectionRegion& region,
                                                 const CorrectionSeam& seam, RegionState& state) {
  // The far ground is seen near the edge of each lens, through the ground plane's last metres of
  // calibration accuracy and past whatever stands on it: block by block its data scatter, while
  // the cameras' light falls off smoothly there. One median over the band outvotes the scatter
  // and still gives the far ground its own gain. Unless it is far from the near ground's: then
  // the far ground is mostly something standing on it (a wall near the car, seen differently by
  // the two cameras), and the near ground's median is carried out to it instead.
  float* values = stepScratch_.data();  // free until dropWorseningSeams()
  std::array<float, 3> far{};
  std::array<float, 3> near{};
  bool haveNear = true;
  for (std::size_t c = 0; c < 3; ++c) {
    for (const bool beyond : {true, false}) {
      std::size_t count = 0;
      for (const auto k : seam.blocks) {
        if (region.dirichlet[k].beyondFloor != beyond || state.measuredValid[k] == 0) continue;
        values[count++] = state.measured[static_cast<std::size_t>(k) * 3 + c];
      }
      if (beyond && count < kMinimumFarBlocks) return;  // the running median as it is
      if (!beyond && count < kMinimumFarBlocks) haveNear = false;
      (beyond ? far : near)[c] = count == 0 ? 0.0f : medianOf(values, count);
    }
  }
  const float spread =
      settings_.field == CorrectionField::kMultiplicative ? kFarBandLogSpread : kFarBandLevelSpread;
  bool plausible = true;
  for (std::size_t c = 0; c < 3; ++c) {
    plausible = plausible && (!haveNear || std::abs(far[c] - near[c]) <= spread);
  }
  const std::array<float, 3>& band = plausible ? far : near;
  for (const auto k : seam.blocks) {
    if (!region.dirichlet[k].beyondFloor || state.filteredValid[k] == 0) continue;
    for (std::size_t c = 0; c < 3; ++c)
      state.filtered[static_cast<std::size_t>(k) * 3 + c] = band[c];
  }
}

void PoissonColourCorrection::measureSeamBlocks(std::size_t part, std::span<const cv::Mat> frames,
                                                PixelFormat format) {
  Configuration& active = *active_;
  const bool multiplicative = settings_.field == CorrectionField::kMultiplicative;
  SeamBlockMeter& meter = meters_[part];
  std::size_t turn = 0;  // of the block, counted over the regions
  for (std::size_t r = 0; r < active.regions.size(); ++r) {
    const CorrectionRegion& region = active.domain.regions[r];
    RegionState& state = active.regions[r];
    const cv::Mat& source = frames[region.source];
    for (std::size_t k = 0; k < region.dirichlet.size(); ++k, ++turn) {
      if (turn % meters_.size() != part) continue;
      const DirichletBlock& d = region.dirichlet[k];
      const cv::Mat& target = frames[d.target];
      state.measuredValid[k] = 0;
      if (source.empty() || target.empty()) continue;
      const SeamBlockLevels levels = meter.measure(
          active.domain, d, SampledImage::of(target, format), SampledImage::of(source, format));
      state.levels[k] = levels;
      state.measuredValid[k] = levels.valid ? 1 : 0;
      for (int c = 0; c < 3; ++c) state.measured[k * 3 + c] = seamValue(levels, c, multiplicative);
    }
  }
}

void PoissonColourCorrection::gatherSeams(std::span<const cv::Mat> frames, PixelFormat format) {
  Configuration& active = *active_;
  const float keep = active.firstFrame ? 0.0f : static_cast<float>(settings_.temporalSmoothing);
  const bool multiplicative = settings_.field == CorrectionField::kMultiplicative;
  // Each part writes only its own blocks' entries. Four parts a thread: a thread that the encoder
  // or the decoders keep from starting leaves its parts to the others instead of being waited for.
  const auto parts = static_cast<int>(meters_.size());
  pool_.parallelFor(
      parts,
      [&](int first, int last) {
        for (int part = first; part < last; ++part) {
          measureSeamBlocks(static_cast<std::size_t>(part), frames, format);
        }
      },
      parts);
  if (balance_) balanceSeams(frames);

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
    farGroundAsOneBand(region, seam, state);
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

void PoissonColourCorrection::balanceSeams(std::span<const cv::Mat> frames) {
  Configuration& active = *active_;
  // Per seam, the median over its measured blocks of log(target / source), per channel: what the
  // balance is fitted to. stepScratch_ holds a seam's blocks four times over.
  float* values = stepScratch_.data();
  std::size_t pairs = 0;
  for (const CorrectionSeam& seam : active.domain.seams) {
    const CorrectionRegion& region = active.domain.regions[seam.region];
    const RegionState& state = active.regions[seam.region];
    if (frames[region.source].empty() || frames[seam.target].empty()) continue;
    CameraPairRatio& pair = pairRatios_[pairs++];
    pair = {region.source, seam.target, {}, 0};
    for (int c = 0; c < 3; ++c) {
      std::size_t count = 0;
      for (const auto k : seam.blocks) {
        if (state.measuredValid[k] == 0) continue;
        values[count++] = seamValue(state.levels[k], c, true);
      }
      pair.weight = static_cast<double>(count);
      pair.logRatio[c] = count == 0 ? 0.0f : medianOf(values, count);
    }
  }
  for (std::size_t c = 0; c < present_.size(); ++c) present_[c] = frames[c].empty() ? 0 : 1;
  balance_->update(std::span(pairRatios_).first(pairs), present_);
  for (const auto& note : balance_->notesOfLastUpdate()) changes_.push_back(note);

  // The levels as the balance leaves them, and the seam data from those.
  const std::vector<cv::Vec3f>& gains = balance_->gains();
  const bool multiplicative = settings_.field == CorrectionField::kMultiplicative;
  for (std::size_t r = 0; r < active.regions.size(); ++r) {
    const CorrectionRegion& region = active.domain.regions[r];
    RegionState& state = active.regions[r];
    for (std::size_t k = 0; k < region.dirichlet.size(); ++k) {
      if (state.measuredValid[k] == 0) continue;
      SeamBlockLevels& levels = state.levels[k];
      levels.source = levels.source.mul(gains[region.source]);
      levels.target = levels.target.mul(gains[region.dirichlet[k].target]);
      for (int c = 0; c < 3; ++c) state.measured[k * 3 + c] = seamValue(levels, c, multiplicative);
    }
  }
}

float PoissonColourCorrection::asItWas(const CorrectionRegion& region, const RegionState& state,
                                       std::size_t block, int channel) const {
  // Without the balance: no field. With it: the field that gives the source the target's gain
  // there (g_t / g_s on the balanced source), so that the seam's two sides keep the step they had
  // uncorrected, times the target's gain.
  const auto gains = cameraGains();
  if (gains.empty()) return 0;
  const float ratio =
      gains[region.dirichlet[block].target][channel] / gains[region.source][channel];
  return settings_.field == CorrectionField::kMultiplicative
             ? std::log(ratio)
             : state.levels[block].source[channel] * (ratio - 1);
}

bool PoissonColourCorrection::dropWorseningSeams() {
  Configuration& active = *active_;
  const auto gains = cameraGains();
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
      // None is the cameras as they are: with the balance, its levels taken back off.
      const cv::Vec3f sourceGain = gains.empty() ? cv::Vec3f(1, 1, 1) : gains[region.source];
      const cv::Vec3f targetGain =
          gains.empty() ? cv::Vec3f(1, 1, 1) : gains[region.dirichlet[k].target];
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
        before += std::abs(levels.target[c] / targetGain[c] - levels.source[c] / sourceGain[c]) / 3;
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
        const auto k = seam.blocks[j];
        for (int c = 0; c < 3; ++c) state.dirichlet[k * 3 + c] = asItWas(region, state, k, c);
      }
    }
    if (report.droppedBlocks == 0) continue;
    noteOnce(active.saidDropped, i,
             fmt::format("seam {}/{}: correcting {} of its {} blocks would make their step worse "
                         "(the seam's: {:.1f} against {:.1f} levels uncorrected): their data is "
                         "dropped ({})",
                         rig_.cameras[region.source].name, rig_.cameras[seam.target].name,
                         report.droppedBlocks, report.blocks, report.stepCorrected,
                         report.stepUncorrected,
                         gains.empty() ? "gain 1 there" : "their step left as it was"));
    report.dropped = whole;
    if (whole) report.stepCorrected = report.stepUncorrected;
    dropped = true;
    resolve_[seam.region] = 1;
  }
  return dropped;
}

}  // namespace surroundd::processing
