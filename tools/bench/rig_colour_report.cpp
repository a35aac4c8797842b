#include "tools/bench/rig_colour_report.hpp"

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
  // The colour stage per frame, as the pipeline runs it: seam data and solve (warm-started from
  // the frame before), then upsampling and applying the field.
  cv::Mat scratch = raw.clone();
  const auto stageMs = interleavedMedians(
      {[&] { correction.update(frames); }, [&] { correction.apply(scratch); }}, kTimingRepeats);

  int masked = 0;
  for (const auto& camera : rig.cameras) masked += camera.bodyMask.empty() ? 0 : 1;
  fmt::print(
      "{}: {} cameras, panorama {}x{}, {} with a body mask, Poisson {} field at scale {:g}\n",
      input.name, rig.cameras.size(), lut.size.width, lut.size.height, masked,
      processing::correctionFieldName(colour.field), colour.scale);
  const processing::PanoramaProjector projector(rig, settings);
  const auto seams = seamLines(rig, settings);
  const auto stepRow = [](const std::array<SeamColourStep, 3>& steps) {
    return fmt::format("{}  {}  {}     {}  {}  {}", levels(steps[0].nearLevels),
                       levels(steps[1].nearLevels), levels(steps[2].nearLevels),
                       levels(steps[0].farLevels), levels(steps[1].farLevels),
                       levels(steps[2].farLevels));
  };
  fmt::print("  {:<14} {:>24}   {:^23}   {:^23}\n", "seam", "misalignment",
             "step near: none gain PLCC", "step far: none gain PLCC");
  for (const auto& seam : seams) {
    const auto alignment = processing::seamMisalignment(rig, frames, settings, seam);
    fmt::print("  {:<14} {:>24}   {}\n", seam.name,
               alignment ? fmt::format("{:.1f} cm at {:.1f} m ({:.2f})", alignment->shiftCm,
                                       alignment->distanceM, alignment->response)
                         : std::string("n/a"),
               stepRow({seamColourStep(raw, lut, settings, seam),
                        seamColourStep(gained, lut, settings, seam),
                        seamColourStep(poisson, lut, settings, seam)}));
  }
  fmt::print("  {:<14} {:>24}   {:^23}   {:^23}\n", "seam", "(both cameras' views)",
             "view near: none gain PLCC", "view far: none gain PLCC");
  for (const auto& seam : seams) {
    fmt::print("  {:<14} {:>24}   {}\n", seam.name, "",
               stepRow({seamViewStep(raw, raw, projector, lut, frames, seam),
                        seamViewStep(raw, gained, projector, lut, frames, seam),
                        seamViewStep(raw, poisson, projector, lut, frames, seam)}));
  }
  const double before = meanLevel(raw, lut);
  fmt::print("  mean level: none {:.1f}, gain {:.1f} ({:+.1f} %), Poisson {:.1f} ({:+.1f} %)\n",
             before, meanLevel(gained, lut), 100 * (meanLevel(gained, lut) / before - 1),
             meanLevel(poisson, lut), 100 * (meanLevel(poisson, lut) / before - 1));
  std::string gainText;
  for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
    const cv::Vec3f g = gains.gains()[c];
    gainText += fmt::format("{}{} {:.2f}/{:.2f}/{:.2f}", gainText.empty() ? "" : ", ",
                            rig.cameras[c].name, g[0], g[1], g[2]);
  }
  fmt::print("  gains (B/G/R): {}\n", gainText);
  double lowest = 1, highest = 1;
  cv::minMaxLoc(correction.field().reshape(1), &lowest, &highest);
  fmt::print("  Poisson field: x{:.2f} .. x{:.2f} at 255\n", 1 + lowest / 255, 1 + highest / 255);
  for (const auto& seam : correction.seams()) {
    fmt::print(
        "    seam {}/{}: {} of {} blocks measured, {} clamped, {} dropped, step {:.1f} -> "
        "{:.1f}{}\n",
        rig.cameras[seam.source].name, rig.cameras[seam.target].name, seam.validBlocks, seam.blocks,
        seam.clampedBlocks, seam.droppedBlocks, seam.stepUncorrected, seam.stepCorrected,
        seam.dropped ? " (all dropped: it would have got worse)" : "");
  }
  fmt::print(
      "  Poisson per frame, {} thread(s): seam data + solve {:.2f} ms, upsample and apply {:.2f} "
      "ms\n",
      pool.threads(), stageMs[0], stageMs[1]);
  for (const auto& note : correction.notes()) fmt::print("    note: {}\n", note);
  for (const auto& note : correction.notesOfLastUpdate()) fmt::print("    note: {}\n", note);
  if (!pictures.empty()) {
    std::filesystem::create_directories(pictures);
    const std::string stem = std::filesystem::path(input.name).stem().string();
    cv::imwrite((pictures / (stem + "-none.png")).string(), raw);
    cv::imwrite((pictures / (stem + "-gain.png")).string(), gained);
    cv::imwrite((pictures / (stem + "-poisson.png")).string(), poisson);
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
