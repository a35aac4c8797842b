#include "tools/bench/stitch_benchmark.hpp"

#include <cstdio>
#include <filesystem>
#include <numbers>
#include <stdexcept>
#include <string>

#include <fmt/format.h>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <unistd.h>

#include "common/ffmpeg_util.hpp"
#include "common/masked_psnr.hpp"
#include "common/work_pool.hpp"
#include "processing/colour/poisson_correction.hpp"
#include "processing/stitch/panorama_lut_cache.hpp"
#include "processing/stitch/stitcher.hpp"
#include "processing/stitch/view_lut.hpp"
#include "processing/surround_mesh.hpp"
#include "render/egl_context.hpp"
#include "render/outputs/encoder_conversion.hpp"
#include "render/surround_view.hpp"
#include "tools/bench/panorama_accuracy.hpp"
#include "tools/bench/recording_truth.hpp"
#include "tools/bench/remap_baseline.hpp"
#include "tools/bench/timing.hpp"

namespace surroundd::bench {
namespace {

struct Accuracy {
  SeamAlignment seams;
  double groundError = 0;  // levels, mean over the ground-truth frames
};

struct ThreadTiming {
  int threads = 0;
  double stitchMs = 0;
  double remapMs = 0;
  double portableMs = 0;  // the stitcher on its portable kernels (kernel_path.hpp)
};

// The same stitch from frames held as a camera hands them over (common/pixel_format.hpp), on
// `threads` threads, through the panorama's LUT and through the top view's: what sampling YUV
// straight costs against sampling BGR.
struct FormatTiming {
  PixelFormat format = PixelFormat::kBgr;
  double panoramaMs = 0;
  double topViewMs = 0;
};

// The top view through its view LUT (processing/stitch/view_lut.hpp) and the Poisson field
// applied to it, against the panorama stitched and corrected, uploaded, drawn and read back, for
// the same picture.
struct TopViewTiming {
  cv::Size size{1280, 720};
  double mapMs = 0;         // OpenGL's part of its set-up, on the pipeline's thread at a switch:
                            // where the view samples the panorama, and its car and background
  double composeS = 0;      // the view LUT from the panorama's and the field's samples, on one
                            // thread (beside the sets)
  double directMs = 0;      // one gather into the picture, the field applied to it
  double directI420Ms = 0;  // the same for an encoder: the field's pass converting it to I420
  double encoderBgrMs = 0;  // what that spares the encoder: its conversion of the BGR picture
  double renderedMs = 0;    // stitch + field + upload + draw + read-back
  double psnr = 0;          // of the direct picture against the rendered one, where both show the
                            // panorama
  std::vector<FormatTiming> formats;
};

struct InputReport {
  std::string name;
  cv::Size camera;
  cv::Size panorama;
  double lutBuildS = 0;
  double lutLoadS = 0;
  std::size_t lutBytes = 0;
  std::vector<ThreadTiming> timings;
  TopViewTiming topView;
  Accuracy bowl;
  Accuracy sphere;
};

cv::Mat readImage(const std::filesystem::path& path) {
  cv::Mat image = cv::imread(path.string(), cv::IMREAD_COLOR);
  if (image.empty()) throw std::runtime_error(fmt::format("cannot read {}", path.string()));
  return image;
}

processing::PanoramaSettings settingsFor(const RecordingTruth& truth,
                                         processing::PanoramaProjection projection) {
  processing::PanoramaSettings settings;
  settings.geometry = truth.panorama;
  settings.projection = projection;
  return settings;
}

Accuracy measureAccuracy(const RecordingTruth& truth, const synth::Scene& scene,
                         const processing::PanoramaSettings& settings, WorkPool& pool) {
  const processing::PanoramaLut lut = processing::buildPanoramaLut(truth.rig, settings, pool);
  processing::Stitcher stitcher(lut, pool);
  Accuracy accuracy;
  accuracy.seams = measureGroundSeams(truth.rig, settings, lut);
  cv::Mat panorama;
  for (const auto& frame : truth.frames) {
    std::vector<cv::Mat> images;
    for (const auto& path : frame.images) images.push_back(readImage(path));
    stitcher.stitch(images, panorama);
    // Pixels no camera sees are not the stitcher's error.
    const cv::Mat ground = trueGroundMask(scene, frame.pose, settings) & lut.validMask();
    accuracy.groundError += meanAbsoluteError(panorama, readImage(frame.panorama), ground);
  }
  accuracy.groundError /= static_cast<double>(truth.frames.size());
  return accuracy;
}

TopViewTiming measureTopView(const processing::Rig& rig,
                             const processing::PanoramaSettings& settings,
                             const processing::PanoramaLut& lut, const std::vector<cv::Mat>& images,
                             WorkPool& pool, int repeats) {
  TopViewTiming timing;
  const processing::PanoramaGeometry& geometry = settings.geometry;
  processing::PoissonColourCorrection correction(rig, settings, lut, {}, pool);
  correction.update(images);
  const render::EglContext gl;
  render::SurroundScene scene(processing::buildSurroundMesh({}, geometry), geometry, {},
                              lut.cameraSizes.front());
  render::SurroundView view(scene, timing.size, render::ViewKind::kTop, {});
  processing::PanoramaLut viewLut;
  cv::Mat positions;
  timing.mapMs = millisecondsOf([&] {
    positions = view.panoramaPositions(0);
    (void)view.stillPicture(0);
  });
  processing::PoissonColourCorrection::ViewSamples fieldSamples;
  timing.composeS = millisecondsOf([&] {
                      WorkPool caller(1);
                      viewLut = processing::composeViewLut(lut, positions, caller);
                      fieldSamples = correction.viewSamples(positions);
                    }) /
                    1000;
  processing::Stitcher stitcher(lut, pool);
  processing::Stitcher direct(viewLut, pool);
  cv::Mat panorama(lut.size, CV_8UC3);
  cv::Mat directPicture(timing.size, CV_8UC3);
  cv::Mat rendered;
  cv::Mat i420;
  const render::EncoderConversion encoderConversion(timing.size, AV_PIX_FMT_YUV420P);
  const ffmpeg::FramePtr encoderFrame(av_frame_alloc());
  if (encoderFrame == nullptr) throw std::runtime_error("out of memory");
  encoderFrame->format = AV_PIX_FMT_YUV420P;
  encoderFrame->width = timing.size.width;
  encoderFrame->height = timing.size.height;
  if (av_frame_get_buffer(encoderFrame.get(), 0) < 0) throw std::runtime_error("out of memory");
  const auto medians =
      interleavedMedians({[&] {
                            direct.stitch(images, directPicture);
                            correction.applyAt(fieldSamples, directPicture);
                          },
                          [&] {
                            direct.stitch(images, directPicture);
                            correction.applyAt(fieldSamples, directPicture, i420);
                          },
                          [&] { (void)encoderConversion.convert(directPicture, *encoderFrame); },
                          [&] {
                            stitcher.stitch(images, panorama);
                            correction.apply(panorama);
                            scene.uploadPanorama(panorama);
                            view.draw(0);
                            rendered = view.collect();
                          }},
                         repeats);
  timing.directMs = medians[0];
  timing.directI420Ms = medians[1];
  timing.encoderBgrMs = medians[2];
  timing.renderedMs = medians[3];
  for (const PixelFormat format :
       {PixelFormat::kBgr, PixelFormat::kYuyv, PixelFormat::kUyvy, PixelFormat::kNv12}) {
    std::vector<cv::Mat> held(images.size());
    for (std::size_t c = 0; c < images.size(); ++c) bgrToHeld(images[c], format, held[c]);
    const auto formatMedians =
        interleavedMedians({[&] { stitcher.stitch(held, format, panorama); },
                            [&] { direct.stitch(held, format, directPicture); }},
                           repeats);
    timing.formats.push_back({format, formatMedians[0], formatMedians[1]});
  }
  const cv::Mat shown = render::SurroundView::panoramaShown(positions);
  timing.psnr = maskedPsnr(directPicture, rendered, shown);
  return timing;
}

InputReport measure(const std::filesystem::path& folder, int threads, int repeats) {
  const RecordingTruth truth = loadRecordingTruth(folder);
  InputReport report;
  report.name = folder.filename().string();
  report.camera = truth.rig.cameras.front().intrinsics.imageSize;
  report.panorama = truth.panorama.size;

  WorkPool pool(threads);
  const auto bowlSettings = settingsFor(truth, processing::PanoramaProjection::kBowl);
  processing::PanoramaLut lut;
  report.lutBuildS =
      millisecondsOf([&] { lut = processing::buildPanoramaLut(truth.rig, bowlSettings, pool); }) /
      1000;
  const auto cacheDir = std::filesystem::temp_directory_path() /
                        fmt::format("surround-bench-{}", static_cast<long>(::getpid()));
  const processing::PanoramaLutCache cache(cacheDir);
  const std::string key = processing::panoramaLutKey(truth.rig, bowlSettings);
  cache.store(key, lut);
  report.lutBytes = std::filesystem::file_size(cache.fileFor(key));
  report.lutLoadS = millisecondsOf([&] { (void)cache.load(key, lut.size); }) / 1000;
  std::filesystem::remove_all(cacheDir);

  std::vector<cv::Mat> images;
  for (const auto& path : truth.frames.front().images) images.push_back(readImage(path));
  const RemapBaseline baseline(lut);
  cv::Mat ours(lut.size, CV_8UC3);
  cv::Mat theirs(lut.size, CV_8UC3);
  cv::Mat portable(lut.size, CV_8UC3);
  for (const int t : threads > 1 ? std::vector<int>{1, threads} : std::vector<int>{1}) {
    WorkPool timedPool(t);
    processing::Stitcher stitcher(lut, timedPool);
    cv::setNumThreads(t);
    const auto medians = interleavedMedians(
        {[&] { stitcher.stitch(images, ours); }, [&] { baseline.stitch(images, theirs); },
         [&] { stitcher.stitch(images, portable, processing::KernelPath::kPortable); }},
        repeats);
    report.timings.push_back({t, medians[0], medians[1], medians[2]});
  }
  cv::setNumThreads(-1);
  report.topView = measureTopView(truth.rig, bowlSettings, lut, images, pool, repeats);

  const synth::Scene scene(truth.seed, truth.seconds);
  report.bowl = measureAccuracy(truth, scene, bowlSettings, pool);
  report.sphere = measureAccuracy(
      truth, scene, settingsFor(truth, processing::PanoramaProjection::kSphere), pool);
  return report;
}

void printText(const std::vector<InputReport>& reports) {
  fmt::print(
      "surround-bench stitch: the LUT stitcher against cv::remap on the same maps (median "
      "ms, same run)\n\n");
  for (const auto& r : reports) {
    fmt::print("{}: 4 x {}x{} -> panorama {}x{}\n", r.name, r.camera.width, r.camera.height,
               r.panorama.width, r.panorama.height);
    fmt::print("  LUT (bowl): build {:.2f} s, cache load {:.3f} s, {:.1f} MB on disk\n",
               r.lutBuildS, r.lutLoadS, static_cast<double>(r.lutBytes) / 1e6);
    for (const auto& t : r.timings) {
      fmt::print(
          "  {} thread{}: stitch {:6.2f} ms ({:5.0f} fps)   cv::remap {:6.2f} ms   "
          "ratio {:.2f}x   {} kernels against portable ({:.2f} ms): {:.2f}x\n",
          t.threads, t.threads > 1 ? "s" : " ", t.stitchMs, 1000 / t.stitchMs, t.remapMs,
          t.stitchMs / t.remapMs, processing::kernelPathName(processing::kNativeKernels),
          t.portableMs, t.stitchMs / t.portableMs);
    }
    const TopViewTiming& top = r.topView;
    fmt::print(
        "  top view {}x{}, {} threads, Poisson field: view LUT {:6.2f} ms ({:5.0f} fps)   stitch "
        "+ render + read-back {:6.2f} ms   ratio {:.2f}x   PSNR against the render {:.1f} dB   "
        "view LUT: mapped by OpenGL in {:.1f} ms, composed on one thread in {:.2f} s\n",
        top.size.width, top.size.height, r.timings.back().threads, top.directMs,
        1000 / top.directMs, top.renderedMs, top.directMs / top.renderedMs, top.psnr, top.mapMs,
        top.composeS);
    fmt::print(
        "  top view for an encoder: gather + field + I420 {:6.2f} ms ({:.2f}x the BGR picture's), "
        "sparing the encoder its BGR -> 4:2:0 conversion ({:.2f} ms): ratio {:.2f}x\n",
        top.directI420Ms, top.directI420Ms / top.directMs, top.encoderBgrMs,
        top.directI420Ms / (top.directMs + top.encoderBgrMs));
    const FormatTiming& bgr = top.formats.front();
    for (const FormatTiming& f : top.formats) {
      fmt::print(
          "  frames held in {:<4}: panorama stitch {:6.2f} ms ({:.2f}x BGR's)   top view gather "
          "{:6.2f} ms ({:.2f}x BGR's)\n",
          toString(f.format), f.panoramaMs, f.panoramaMs / bgr.panoramaMs, f.topViewMs,
          f.topViewMs / bgr.topViewMs);
    }
    for (const auto& [name, a] : {std::pair{"bowl  ", r.bowl}, std::pair{"sphere", r.sphere}}) {
      fmt::print(
          "  {}: ground seams {:.2f} px mean, {:.2f} px max ({} seam pixels); error vs "
          "true panorama over the ground {:.2f} levels\n",
          name, a.seams.meanPx, a.seams.maxPx, a.seams.samples, a.groundError);
    }
    fmt::print("\n");
  }
}

void printJson(const std::vector<InputReport>& reports) {
  fmt::print("{{\"stitch\": [");
  for (std::size_t i = 0; i < reports.size(); ++i) {
    const auto& r = reports[i];
    std::string timings;
    for (const auto& t : r.timings) {
      timings += fmt::format(
          "{}{{\"threads\": {}, \"stitch_ms\": {:.4f}, \"remap_ms\": {:.4f}, "
          "\"ratio\": {:.4f}, \"portable_kernels_ms\": {:.4f}}}",
          timings.empty() ? "" : ", ", t.threads, t.stitchMs, t.remapMs, t.stitchMs / t.remapMs,
          t.portableMs);
    }
    std::string formats;
    for (const auto& f : r.topView.formats) {
      formats +=
          fmt::format("{}{{\"format\": \"{}\", \"panorama_ms\": {:.4f}, \"top_view_ms\": {:.4f}}}",
                      formats.empty() ? "" : ", ", toString(f.format), f.panoramaMs, f.topViewMs);
    }
    const auto accuracy = [](const Accuracy& a) {
      return fmt::format(
          "{{\"seam_mean_px\": {:.4f}, \"seam_max_px\": {:.4f}, \"seam_samples\": "
          "{}, \"ground_mae_levels\": {:.4f}}}",
          a.seams.meanPx, a.seams.maxPx, a.seams.samples, a.groundError);
    };
    fmt::print(
        "{}\n  {{\"input\": \"{}\", \"camera\": [{}, {}], \"panorama\": [{}, {}], "
        "\"lut_build_s\": {:.4f}, \"lut_load_s\": {:.4f}, \"lut_bytes\": {}, "
        "\"timings\": [{}], \"top_view\": {{\"size\": [{}, {}], \"view_lut_ms\": {:.4f}, "
        "\"view_lut_i420_ms\": {:.4f}, \"encoder_bgr_ms\": {:.4f}, "
        "\"rendered_ms\": {:.4f}, \"psnr_db\": {:.2f}, \"map_ms\": {:.4f}, \"compose_s\": {:.4f}, "
        "\"held_formats\": "
        "[{}]}}, \"bowl\": {}, "
        "\"sphere\": {}}}",
        i == 0 ? "" : ",", r.name, r.camera.width, r.camera.height, r.panorama.width,
        r.panorama.height, r.lutBuildS, r.lutLoadS, r.lutBytes, timings, r.topView.size.width,
        r.topView.size.height, r.topView.directMs, r.topView.directI420Ms, r.topView.encoderBgrMs,
        r.topView.renderedMs, r.topView.psnr, r.topView.mapMs, r.topView.composeS, formats,
        accuracy(r.bowl), accuracy(r.sphere));
  }
  fmt::print("\n]}}\n");
}

}  // namespace

int runStitchBenchmark(const StitchBenchmarkOptions& options) {
  std::vector<InputReport> reports;
  for (const auto& folder : options.recordings) {
    if (!options.json) std::fprintf(stderr, "measuring %s ...\n", folder.string().c_str());
    reports.push_back(measure(folder, options.threads, options.repeats));
  }
  if (options.json) {
    printJson(reports);
  } else {
    printText(reports);
  }
  return 0;
}

}  // namespace surroundd::bench
