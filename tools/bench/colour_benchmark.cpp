#include "tools/bench/colour_benchmark.hpp"

#include <cstdio>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "capture/file_source.hpp"
#include "common/work_pool.hpp"
#include "processing/colour/gain_compensation.hpp"
#include "processing/colour/poisson_correction.hpp"
#include "processing/stitch/stitcher.hpp"
#include "tools/bench/panorama_accuracy.hpp"
#include "tools/bench/poisson_benchmark.hpp"
#include "tools/bench/recording_truth.hpp"
#include "tools/bench/rig_colour_report.hpp"
#include "tools/bench/timing.hpp"

namespace surroundd::bench {
namespace {

// The first frame of each camera's video: the cameras' real photometrics.
std::vector<cv::Mat> firstVideoFrames(const RecordingTruth& truth) {
  std::vector<cv::Mat> frames;
  for (const auto& video : truth.videos) {
    capture::FileSource source("bench", {video, 30.0, false, capture::Pacing::kAsFastAsPossible});
    capture::Frame frame;
    frame.image.create(source.frameSize(), CV_8UC3);
    if (source.read(frame) != capture::ReadStatus::kFrame) {
      throw std::runtime_error(fmt::format("cannot read a frame of {}", video.string()));
    }
    frames.push_back(frame.image);
  }
  return frames;
}

void measure(const std::filesystem::path& folder, const ColourBenchmarkOptions& options) {
  const RecordingTruth truth = loadRecordingTruth(folder);
  WorkPool pool(options.threads);
  processing::PanoramaSettings settings;
  settings.geometry = truth.panorama;
  const processing::PanoramaLut lut = processing::buildPanoramaLut(truth.rig, settings, pool);
  processing::Stitcher stitcher(lut, pool);
  const std::vector<cv::Mat> frames = firstVideoFrames(truth);
  cv::Mat raw;
  stitcher.stitch(frames, raw);
  const synth::Scene scene(truth.seed, truth.seconds);
  const cv::Mat ground = trueGroundMask(scene, truth.frames.front().pose, settings);
  // Against the target cameras as the panorama shows them (gain compensation changes them too).
  const auto seamError = [&](const cv::Mat& panorama, const std::vector<cv::Mat>& targets) {
    return seamColourError(panorama, targets, truth.rig, settings, lut, ground);
  };

  const cv::Size camera = truth.rig.cameras.front().intrinsics.imageSize;
  fmt::print("{}: 4 x {}x{} -> panorama {}x{}\n", folder.filename().string(), camera.width,
             camera.height, lut.size.width, lut.size.height);
  processing::GainCompensation gains(lut, pool);
  gains.update(frames);
  cv::Mat gained = raw.clone();
  gains.apply(gained);
  fmt::print(
      "  colour step across the seams (true ground): {:.2f} levels uncorrected, {:.2f} with "
      "gain compensation\n",
      seamError(raw, frames), seamError(gained, framesWithGains(frames, gains.gains())));

  for (const double scale : {0.25, 0.125}) {
    processing::ColourCorrectionSettings correctionSettings;
    correctionSettings.scale = scale;
    std::unique_ptr<processing::PoissonColourCorrection> correction;
    const double setupMs = millisecondsOf([&] {
      correction = std::make_unique<processing::PoissonColourCorrection>(truth.rig, settings, lut,
                                                                         correctionSettings, pool);
    });
    for (const auto& note : correction->notes()) fmt::print("    note: {}\n", note);
    if (correction->domain().regions.empty()) continue;
    const auto& region = correction->domain().regions.front();
    fmt::print("  scale {:g}: {} regions, set-up {:.1f} ms (domain, solvers); solver '{}'\n", scale,
               correction->domain().regions.size(), setupMs, correction->solverNames());
    PoissonBenchmarkOptions solverOptions;
    solverOptions.repeats = options.repeats;
    fmt::print("    the front region ({} unknowns in {}x{}):\n{}", region.system.unknowns(),
               region.system.size.width, region.system.size.height,
               formatPoissonTimings(region.system.size,
                                    benchmarkPoissonSolvers(region.system, solverOptions)));
    for (const auto field :
         {processing::CorrectionField::kMultiplicative, processing::CorrectionField::kAdditive}) {
      correctionSettings.field = field;
      correction = std::make_unique<processing::PoissonColourCorrection>(truth.rig, settings, lut,
                                                                         correctionSettings, pool);
      cv::Mat corrected = raw.clone();
      const auto medians = interleavedMedians(
          {[&] { correction->update(frames); }, [&] { correction->apply(corrected); },
           [&] { correction->apply(corrected, processing::KernelPath::kPortable); }},
          options.repeats);
      raw.copyTo(corrected);
      correction->apply(corrected);
      fmt::print(
          "    per frame, {} field, {} threads: seam data + solve {:.2f} ms, upsample and apply "
          "{:.2f} ms ({} kernels; portable {:.2f} ms, {:.2f}x); colour step across the seams "
          "{:.2f} levels\n",
          processing::correctionFieldName(field), options.threads, medians[0], medians[1],
          processing::kernelPathName(processing::kNativeKernels), medians[2],
          medians[1] / medians[2], seamError(corrected, frames));
    }
    // Cameras far apart (the generator's extreme photometrics) need gains past the default
    // gain_range: the same correction with the range a config would widen to.
    correctionSettings.field = processing::CorrectionField::kMultiplicative;
    correctionSettings.minGain = 0.25;
    correctionSettings.maxGain = 4.0;
    processing::PoissonColourCorrection wide(truth.rig, settings, lut, correctionSettings, pool);
    wide.update(frames);
    cv::Mat corrected = raw.clone();
    wide.apply(corrected);
    fmt::print(
        "    multiplicative field with gain_range [0.25, 4]: colour step across the seams "
        "{:.2f} levels\n",
        seamError(corrected, frames));
  }
  // Per seam, as on any rig: misalignment, and the step next to each seam on near and far ground.
  reportRigColour({folder.filename().string(), truth.rig, settings, {}, frames}, pool);
}

}  // namespace

int runColourBenchmark(const ColourBenchmarkOptions& options) {
  fmt::print("surround-bench colour: Poisson local colour correction (medians, same run)\n\n");
  for (const auto& folder : options.recordings) measure(folder, options);
  return 0;
}

}  // namespace surroundd::bench
