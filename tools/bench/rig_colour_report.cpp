#include "tools/bench/rig_colour_report.hpp"

#include <array>
#include <span>
#include <string>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "capture/file_source.hpp"
#include "common/work_pool.hpp"
#include "daemon/config/config.hpp"
#include "daemon/config/panorama_setup.hpp"
#include "processing/colour/gain_compensation.hpp"
#include "processing/colour/poisson_correction.hpp"
#include "processing/stitch/stitcher.hpp"
#include "tools/bench/seam_measures.hpp"
#include "tools/bench/timing.hpp"

namespace surroundd::bench {
namespace {

// Turns of the per-frame timing (medians).
constexpr int kTimingRepeats = 21;

std::vector<cv::Mat> firstFrames(const daemon::Config& config) {
  std::vector<cv::Mat> frames;
  for (const auto& camera : config.cameras) {
    if (!camera.replayedFile()) {
      throw std::runtime_error(fmt::format("{}: camera '{}' is live; the report needs files",
                                           config.file.string(), camera.calibration.name));
    }
    capture::FileSource source(camera.calibration.name, *camera.replayedFile());
    capture::Frame frame;
    frame.image.create(source.frameSize(), CV_8UC3);
    if (source.read(frame) != capture::ReadStatus::kFrame) {
      throw std::runtime_error(
          fmt::format("cannot read a frame of {}", camera.replayedFile()->path.string()));
    }
    frames.push_back(frame.image);
  }
  return frames;
}

std::string levels(const std::optional<double>& value) {
  return value ? fmt::format("{:5.1f}", *value) : std::string("  n/a");
}

}  // namespace

RigColourInput rigColourInput(const std::filesystem::path& configFile, WorkPool& pool) {
  const daemon::Config config = daemon::loadConfig(configFile);
  return {configFile.filename().string(), daemon::rigOf(config, pool),
          daemon::panoramaSettings(config), config.colour.poisson, firstFrames(config)};
}

void reportRigColour(const RigColourInput& input, WorkPool& pool,
                     const std::filesystem::path& pictures) {
  const processing::Rig& rig = input.rig;
  const processing::PanoramaSettings& settings = input.panorama;
  const std::vector<cv::Mat>& frames = input.frames;
  const processing::PanoramaLut lut = processing::buildPanoramaLut(rig, settings, pool);
  processing::Stitcher stitcher(lut, pool);
  cv::Mat raw;
  stitcher.stitch(frames, raw);

  const auto& colour = input.colour;
  cv::Mat gained = raw.clone();
  processing::GainCompensation gains(lut, pool, colour.minGain, colour.maxGain);
  gains.update(frames);
  gains.apply(gained);
  cv::Mat poisson = raw.clone();
  processing::PoissonColourCorrection correction(rig, settings, lut, colour, pool);
  correction.update(frames);
  correction.apply(poisson);
  // Poisson after the global balance (colour_correction.balance), whatever the config says.
  cv::Mat balanced = raw.clone();
  auto balancedColour = colour;
  balancedColour.balance = true;
  processing::PoissonColourCorrection balancing(rig, settings, lut, balancedColour, pool);
  balancing.update(frames);
  balancing.apply(balanced);
  const std::array<const cv::Mat*, 4> methods{&raw, &gained, &poisson, &balanced};
  // The colour stage per frame, as the pipeline runs it: seam data and solve (warm-started from
  // the frame before), then upsampling and applying the field; the same with the balance.
  cv::Mat scratch = raw.clone();
  const auto stageMs =
      interleavedMedians({[&] { correction.update(frames); }, [&] { correction.apply(scratch); },
                          [&] { balancing.update(frames); }, [&] { balancing.apply(scratch); }},
                         kTimingRepeats);

  int masked = 0;
  for (const auto& camera : rig.cameras) masked += camera.bodyMask.empty() ? 0 : 1;
  fmt::print(
      "{}: {} cameras, panorama {}x{}, {} with a body mask, Poisson {} field at scale {:g}\n",
      input.name, rig.cameras.size(), lut.size.width, lut.size.height, masked,
      processing::correctionFieldName(colour.field), colour.scale);
  const processing::PanoramaProjector projector(rig, settings);
  const auto seams = seamLines(rig, settings);
  // Per method (none, gain, PLCC: Poisson, bal.: balance + Poisson), near then far.
  const auto stepRow = [](const auto& step) {
    std::string near, far;
    for (const SeamColourStep& s : step) {
      near += levels(s.nearLevels) + "  ";
      far += levels(s.farLevels) + "  ";
    }
    return near + "   " + far;
  };
  const std::string heading = "none gain PLCC bal.";
  fmt::print("  {:<14} {:>24}   step near: {:<17}   step far: {}\n", "seam", "misalignment",
             heading, heading);
  for (const auto& seam : seams) {
    const auto alignment = processing::seamMisalignment(rig, frames, settings, seam);
    std::array<SeamColourStep, methods.size()> steps;
    for (std::size_t m = 0; m < methods.size(); ++m) {
      steps[m] = seamColourStep(*methods[m], lut, settings, seam);
    }
    fmt::print("  {:<14} {:>24}   {}\n", seam.name,
               alignment ? fmt::format("{:.1f} cm at {:.1f} m ({:.2f})", alignment->shiftCm,
                                       alignment->distanceM, alignment->response)
                         : std::string("n/a"),
               stepRow(steps));
  }
  fmt::print("  {:<14} {:>24}   view near: {:<17}   view far: {}\n", "seam",
             "(both cameras' views)", heading, heading);
  for (const auto& seam : seams) {
    std::array<SeamColourStep, methods.size()> steps;
    for (std::size_t m = 0; m < methods.size(); ++m) {
      steps[m] = seamViewStep(raw, *methods[m], projector, lut, frames, seam);
    }
    fmt::print("  {:<14} {:>24}   {}\n", seam.name, "", stepRow(steps));
  }
  const double before = meanLevel(raw, lut);
  const auto change = [&](const cv::Mat& picture) {
    return fmt::format("{:.1f} ({:+.1f} %)", meanLevel(picture, lut),
                       100 * (meanLevel(picture, lut) / before - 1));
  };
  fmt::print("  mean level: none {:.1f}, gain {}, Poisson {}, balance + Poisson {}\n", before,
             change(gained), change(poisson), change(balanced));
  fmt::print(
      "  chroma spread across cameras (a*b*, ground): none {:.2f}, gain {:.2f}, Poisson {:.2f}, "
      "balance + Poisson {:.2f}\n",
      chromaSpread(raw, lut, settings), chromaSpread(gained, lut, settings),
      chromaSpread(poisson, lut, settings), chromaSpread(balanced, lut, settings));
  const auto gainsText = [&](std::span<const cv::Vec3f> perCamera) {
    std::string text;
    for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
      text += fmt::format("{}{} {:.2f}/{:.2f}/{:.2f}", text.empty() ? "" : ", ",
                          rig.cameras[c].name, perCamera[c][0], perCamera[c][1], perCamera[c][2]);
    }
    return text;
  };
  fmt::print("  gains (B/G/R): {}\n", gainsText(gains.gains()));
  fmt::print("  balance (B/G/R): {}\n", gainsText(balancing.cameraGains()));
  double lowest = 1, highest = 1;
  cv::minMaxLoc(correction.field().reshape(1), &lowest, &highest);
  fmt::print("  Poisson field: x{:.2f} .. x{:.2f} at 255\n", 1 + lowest / 255, 1 + highest / 255);
  const auto printSeams = [&](const processing::PoissonColourCorrection& method) {
    for (const auto& seam : method.seams()) {
      fmt::print(
          "    seam {}/{}: {} of {} blocks measured, {} clamped, {} dropped, step {:.1f} -> "
          "{:.1f}{}\n",
          rig.cameras[seam.source].name, rig.cameras[seam.target].name, seam.validBlocks,
          seam.blocks, seam.clampedBlocks, seam.droppedBlocks, seam.stepUncorrected,
          seam.stepCorrected, seam.dropped ? " (all dropped: it would have got worse)" : "");
    }
  };
  printSeams(correction);
  fmt::print("  balance + Poisson:\n");
  printSeams(balancing);
  fmt::print(
      "  Poisson per frame, {} thread(s): seam data + solve {:.2f} ms, upsample and apply {:.2f} "
      "ms; balance + Poisson {:.2f} and {:.2f} ms\n",
      pool.threads(), stageMs[0], stageMs[1], stageMs[2], stageMs[3]);
  for (const auto& note : correction.notes()) fmt::print("    note: {}\n", note);
  for (const auto& note : correction.notesOfLastUpdate()) fmt::print("    note: {}\n", note);
  if (!pictures.empty()) {
    std::filesystem::create_directories(pictures);
    const std::string stem = std::filesystem::path(input.name).stem().string();
    cv::imwrite((pictures / (stem + "-none.png")).string(), raw);
    cv::imwrite((pictures / (stem + "-gain.png")).string(), gained);
    cv::imwrite((pictures / (stem + "-poisson.png")).string(), poisson);
    cv::imwrite((pictures / (stem + "-balance.png")).string(), balanced);
    for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
      if (rig.cameras[c].bodyMask.empty()) continue;
      cv::imwrite((pictures / (stem + "-mask-" + rig.cameras[c].name + ".png")).string(),
                  rig.cameras[c].bodyMask);
    }
    fmt::print("  pictures in {}\n", pictures.string());
  }
  fmt::print("\n");
}

}  // namespace surroundd::bench
