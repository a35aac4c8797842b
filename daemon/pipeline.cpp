#include "daemon/pipeline.hpp"

#include <algorithm>
#include <array>

#include <spdlog/spdlog.h>

#include "capture/file_source.hpp"
#include "capture/libcamera_source.hpp"
#include "capture/v4l2_source.hpp"
#include "daemon/panorama_setup.hpp"

namespace surroundd::daemon {
namespace {

// Between checks of the stop flag while a camera has nothing to deliver. Live, the wait is short:
// the other cameras' frames must not wait behind a late one past the set's deadline.
constexpr std::chrono::milliseconds kCameraWait{200};
constexpr std::chrono::milliseconds kLiveCameraWait{2};
constexpr std::chrono::seconds kProgressInterval{10};

std::vector<std::unique_ptr<capture::CameraStream>> openCameras(const Config& config) {
  // Each camera's queue, plus one frame waiting in the synchronizer and one being composed.
  const auto poolFrames = static_cast<std::size_t>(config.capture.queueFrames) + 2;
  std::vector<std::unique_ptr<capture::CameraStream>> cameras;
  for (const auto& camera : config.cameras) {
    const auto& name = camera.calibration.name;
    std::unique_ptr<capture::FrameSource> source;
    std::string origin;
    int maxConsecutiveFaults = 30;  // a replay that keeps failing ends
    if (camera.libcamera) {
      source = std::make_unique<capture::LibcameraSource>(name, *camera.libcamera);
      origin = fmt::format("libcamera {}", camera.libcamera->camera);
      maxConsecutiveFaults = 0;
    } else if (camera.device) {
      auto device = std::make_unique<capture::V4l2Source>(name, *camera.device);
      origin = fmt::format("{} ({})", camera.device->device.string(),
                           capture::toString(device->format()));
      source = std::move(device);
      maxConsecutiveFaults = 0;  // a live camera is reopened until it is back
    } else {
      auto settings = *camera.source;
      settings.pacing = config.capture.pacing;
      origin = settings.path.string();
      source = std::make_unique<capture::FileSource>(name, settings);
    }
    const cv::Size calibrated = camera.calibration.intrinsics.imageSize;
    if (source->frameSize() != calibrated) {
      throw std::runtime_error(
          fmt::format("camera '{}': {} has {}x{} frames but the lens is calibrated for {}x{}", name,
                      origin, source->frameSize().width, source->frameSize().height,
                      calibrated.width, calibrated.height));
    }
    spdlog::info("camera '{}': {} ({}x{}, {:.2f} fps)", name, origin, source->frameSize().width,
                 source->frameSize().height,
                 1e9 / static_cast<double>(source->nominalPeriod().count()));
    cameras.push_back(std::make_unique<capture::CameraStream>(name, std::move(source), poolFrames,
                                                              maxConsecutiveFaults));
  }
  return cameras;
}

std::vector<std::string> cameraNames(const Config& config) {
  std::vector<std::string> names;
  for (const auto& camera : config.cameras) names.push_back(camera.calibration.name);
  return names;
}

std::unique_ptr<render::FrameSink> openSink(const OutputConfig& output, cv::Size videoSize,
                                            double nominalFps) {
  if (output.path.has_parent_path()) std::filesystem::create_directories(output.path.parent_path());
  if (output.kind == OutputKind::kSnapshot) {
    return std::make_unique<render::SnapshotSink>(
        output.path, std::chrono::duration_cast<std::chrono::nanoseconds>(
                         std::chrono::duration<double>(output.atSeconds)));
  }
  render::VideoEncoderSettings settings;
  settings.path = output.path;
  settings.size = videoSize;
  settings.nominalFps = nominalFps;
  settings.crf = output.crf;
  settings.preset = output.preset;
  settings.pixelFormat = output.pixelFormat;
  return std::make_unique<render::VideoFileSink>(std::move(settings));
}

}  // namespace

const char* toString(Stage stage) {
  constexpr std::array<const char*, static_cast<std::size_t>(Stage::kCount)> kNames{
      "sync", "mosaic", "stitch", "correct", "render", "read-back", "output"};
  return kNames.at(static_cast<std::size_t>(stage));
}

Pipeline::Pipeline(const Config& config)
    : cameras_(openCameras(config)),
      synchronizer_(cameras_.size(),
                    std::chrono::duration_cast<capture::Timestamp>(
                        std::chrono::duration<double, std::milli>(config.capture.syncToleranceMs))),
      live_(std::ranges::any_of(config.cameras, [](const RigCamera& c) { return c.live(); })),
      lateAfter_(std::chrono::duration_cast<capture::Timestamp>(
          std::chrono::duration<double, std::milli>(config.capture.lateAfterMs))),
      health_(cameras_.size()),
      pool_(config.pipeline.threads),
      mosaic_(cv::Size(config.render.widthPx, config.render.heightPx), cameraNames(config)),
      canvas_(mosaic_.outputSize(), CV_8UC3, cv::Scalar::all(0)) {
  const auto configured = [&](OutputStream stream) {
    return std::ranges::any_of(config.outputs, [&](const auto& o) { return o.stream == stream; });
  };
  if (configured(OutputStream::kPanorama) || configured(OutputStream::kSurround)) {
    lut_ = std::make_unique<processing::PanoramaLut>(obtainPanoramaLut(config, pool_));
    stitcher_ = std::make_unique<processing::Stitcher>(*lut_, pool_);
    ownership_ = std::make_unique<processing::PanoramaOwnership>(*lut_);
    panorama_.create(lut_->size, CV_8UC3);
    for (const auto& size : lut_->cameraSizes) {
      blackFrames_.emplace_back(size, CV_8UC3, cv::Scalar::all(0));
    }
    frames_.resize(cameras_.size());
    stitchInputs_.resize(cameras_.size());
    setUpColourCorrection(config);
  }
  if (configured(OutputStream::kSurround)) setUpSurround(config);
  const double nominalFps = 1e9 / static_cast<double>(cameras_.front()->nominalPeriod().count());
  for (const auto& output : config.outputs) {
    if (output.kind == OutputKind::kRecording) {
      recorders_.push_back(std::make_unique<RigRecorder>(
          RecordingSettings{output.path, output.lossless, output.crf, output.preset},
          config.cameras, nominalFps));
      continue;
    }
    const cv::Size size =
        output.stream == OutputStream::kPanorama ? lut_->size : mosaic_.outputSize();
    Output out;
    out.stream = output.stream;
    out.sink = openSink(output, size, nominalFps);
    if (output.stream == OutputStream::kSurround) {
      out.view = std::make_unique<render::SurroundView>(
          *scene_, size, output.view.value_or(config.render.view), config.render.views);
    }
    outputs_.push_back(std::move(out));
  }
}

void Pipeline::setUpColourCorrection(const Config& config) {
  const processing::Rig rig = rigOf(config);
  if (config.colour.method == ColourMethod::kGain) {
    gains_ = std::make_unique<processing::GainCompensation>(*lut_, pool_);
    spdlog::info("colour correction: global gain compensation");
  } else if (config.colour.method == ColourMethod::kPoisson) {
    const processing::ColourCorrectionSettings settings{config.colour.scale, config.colour.solver,
                                                        config.colour.tolerance,
                                                        config.colour.temporalSmoothing};
    poisson_ = std::make_unique<processing::PoissonColourCorrection>(rig, panoramaSettings(config),
                                                                     *lut_, settings, pool_);
    for (const auto& note : poisson_->notes()) spdlog::warn("colour correction: {}", note);
    spdlog::info("colour correction: Poisson, {} region(s) at scale {:g}, solver {}",
                 poisson_->domain().regions.size(), config.colour.scale, poisson_->solverNames());
  }
}

void Pipeline::setUpSurround(const Config& config) {
  gl_ = std::make_unique<render::EglContext>(config.render.platform);
  spdlog::info("render: {}", gl_->description());
  const processing::PanoramaSettings panorama = panoramaSettings(config);
  processing::SurroundMesh mesh;
  try {
    mesh = processing::buildSurroundMesh(meshSettings(config), panorama.geometry);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(fmt::format("{}: {}", config.file.string(), e.what()));
  }
  const auto names = cameraNames(config);
  const auto split = std::ranges::find(names, config.render.splitCamera);
  splitCamera_ = split == names.end() ? 0 : static_cast<std::size_t>(split - names.begin());
  scene_ = std::make_unique<render::SurroundScene>(mesh, panorama.geometry, config.render.car,
                                                   lut_->cameraSizes.at(splitCamera_));
  spdlog::info("render: {} mesh of {} triangles, split view shows '{}'",
               config.mesh.model == MeshModel::kBowl   ? "bowl"
               : config.mesh.model == MeshModel::kFlat ? "flat"
                                                       : "sphere360",
               mesh.indices.size() / 3, names[splitCamera_]);
}

const cv::Mat& Pipeline::imageOf(OutputStream stream) const {
  return stream == OutputStream::kPanorama ? panorama_ : canvas_;
}

Pipeline::~Pipeline() = default;

void Pipeline::setView(ViewKind view) {
  for (auto& output : outputs_) {
    if (output.view) output.view->setView(view);
  }
}

std::string Pipeline::statusLine(std::uint64_t frameSets,
                                 std::chrono::duration<double> elapsed) const {
  std::string cameras;
  for (std::size_t c = 0; c < cameras_.size(); ++c) {
    cameras += fmt::format("{}{} {}", c == 0 ? "" : ", ", cameras_[c]->name(),
                           capture::toString(health_.health(c)));
  }
  return fmt::format(
      "{:.1f} fps, {} frames dropped by sync, mean skew {:.1f} ms; {}",
      elapsed.count() > 0 ? static_cast<double>(frameSets) / elapsed.count() : 0.0,
      synchronizer_.stats().totalDropped(),
      std::chrono::duration<double, std::milli>(synchronizer_.stats().meanSpread()).count(),
      cameras);
}

RunSummary Pipeline::run(const std::atomic<bool>& stop, ServiceNotifier* service) {
  RunSummary summary;
  for (auto& camera : cameras_) camera->start();
  const auto start = std::chrono::steady_clock::now();
  auto nextProgress = start + kProgressInterval;
  while (!stop && !synchronizer_.finished()) {
    auto since = std::chrono::steady_clock::now();
    fillNeeds(stop);
    timed(Stage::kSync, since);
    while (auto set = synchronizer_.pop()) {
      process(*set);
      ++summary.frameSets;
    }
    // Live timestamps are CLOCK_MONOTONIC, which is steady_clock here.
    if (live_) {
      if (auto set = synchronizer_.popLate(std::chrono::steady_clock::now().time_since_epoch(),
                                           lateAfter_)) {
        process(*set);
        ++summary.frameSets;
      }
    }
    const auto now = std::chrono::steady_clock::now();
    if (now >= nextProgress) {
      nextProgress += kProgressInterval;
      spdlog::info("{} frame sets, {}", summary.frameSets,
                   statusLine(summary.frameSets, now - start));
    }
    if (service != nullptr) {
      service->tick(now, summary.frameSets);
      if (service->statusDue(now)) service->status(now, statusLine(summary.frameSets, now - start));
    }
  }
  if (service != nullptr) service->stopping();
  if (stop) spdlog::info("stop requested: finalizing outputs");
  finish(summary);
  summary.wallTime = std::chrono::steady_clock::now() - start;
  return summary;
}

void Pipeline::timed(Stage stage, std::chrono::steady_clock::time_point& since) {
  const auto now = std::chrono::steady_clock::now();
  stageTime_[static_cast<std::size_t>(stage)] += now - since;
  since = now;
}

template <typename Step>
void Pipeline::guarded(Output& output, Step&& step) {
  if (!output.sink) return;
  try {
    step();
  } catch (const std::exception& e) {
    spdlog::error("output failed, dropping it: {}", e.what());
    ++failedSinks_;
    output.sink.reset();
  }
}

void Pipeline::fillNeeds(const std::atomic<bool>& stop) {
  for (std::size_t c = 0; c < cameras_.size() && !stop; ++c) {
    if (!synchronizer_.needs(c)) continue;
    capture::FrameRef frame;
    switch (cameras_[c]->next(frame, live_ ? kLiveCameraWait : kCameraWait)) {
      case capture::CameraStream::Next::kFrame:
        synchronizer_.offer(c, std::move(frame));
        break;
      case capture::CameraStream::Next::kEnded:
        synchronizer_.end(c);
        break;
      case capture::CameraStream::Next::kTimeout:
        break;
    }
  }
}

bool Pipeline::shows(OutputStream stream) const {
  return std::ranges::any_of(outputs_,
                             [&](const Output& o) { return o.stream == stream && o.sink; });
}

void Pipeline::process(const capture::FrameSet& set) {
  auto since = std::chrono::steady_clock::now();
  if (!firstTimestamp_) firstTimestamp_ = set.timestamp;
  lastStreamTime_ = set.timestamp - *firstTimestamp_;
  followHealth(set);
  for (auto& recorder : recorders_) {
    if (!recorder) continue;
    try {
      recorder->record(set);
    } catch (const std::exception& e) {
      spdlog::error("recording failed, dropping it: {}", e.what());
      ++failedSinks_;
      recorder.reset();
    }
  }
  std::array<const cv::Mat*, capture::kMaxCameras> images{};
  for (std::size_t c = 0; c < set.cameraCount; ++c) {
    images[c] = set.frame(c) != nullptr ? &set.frame(c)->image : nullptr;
  }
  // Every set's mosaic, even when no sink wants this frame: it may be the last one, which a
  // snapshot asked for after the end is given. (Surround views are rendered again at the end.)
  if (shows(OutputStream::kMosaic)) {
    mosaic_.compose(std::span(images.data(), set.cameraCount), canvas_,
                    std::span(faults_.data(), set.cameraCount));
    timed(Stage::kMosaic, since);
  }
  // The panorama is made for every set, wanted or not: colour correction follows it over time.
  if (stitcher_) {
    for (std::size_t c = 0; c < set.cameraCount; ++c) {
      // A faulty camera's picture would pull its neighbours' colours: correction goes without it.
      frames_[c] = images[c] != nullptr && faults_[c] == nullptr ? *images[c] : cv::Mat();
      stitchInputs_[c] = images[c] != nullptr ? *images[c] : blackFrames_[c];
    }
    stitcher_->stitch(stitchInputs_, panorama_);
    timed(Stage::kStitch, since);
    if (poisson_) {
      poisson_->update(frames_);
      for (const auto& note : poisson_->notesOfLastUpdate()) {
        spdlog::warn("colour correction: {}", note);
      }
      poisson_->apply(panorama_);
    } else if (gains_) {
      gains_->update(frames_);
      gains_->apply(panorama_);
    }
    for (std::size_t c = 0; c < set.cameraCount; ++c) {
      if (faults_[c] != nullptr) ownership_->markFaulty(panorama_, c);
    }
    timed(Stage::kCorrect, since);
  }
  deliverSurround();
  renderSurround(set, lastStreamTime_);
  since = std::chrono::steady_clock::now();
  for (auto& output : outputs_) {
    if (output.view || !output.sink || !output.sink->wantsFrame(lastStreamTime_)) continue;
    guarded(output, [&] { output.sink->consume(imageOf(output.stream), lastStreamTime_); });
  }
  timed(Stage::kOutput, since);
}

void Pipeline::followHealth(const capture::FrameSet& set) {
  for (const capture::HealthChange& change : health_.observe(set, synchronizer_.stats())) {
    const auto& name = cameras_[change.camera]->name();
    const double at = std::chrono::duration<double>(lastStreamTime_).count();
    if (change.to == capture::CameraHealth::kOk) {
      spdlog::info("camera '{}': back to normal at {:.3f} s (was {})", name, at,
                   capture::toString(change.from));
      faults_[change.camera] = nullptr;
    } else {
      spdlog::warn("camera '{}': {} at {:.3f} s; its part of the view is marked", name,
                   capture::toString(change.to), at);
      faults_[change.camera] = capture::toString(change.to);
    }
    healthChanges_.push_back(change);
    healthChanges_.back().at = lastStreamTime_;
  }
}

void Pipeline::renderSurround(const capture::FrameSet& set, std::chrono::nanoseconds streamTime) {
  if (!scene_) return;
  auto since = std::chrono::steady_clock::now();
  bool panoramaUploaded = false;
  bool cameraUploaded = false;
  for (auto& output : outputs_) {
    if (!output.view || !output.sink || !output.sink->wantsFrame(streamTime)) continue;
    guarded(output, [&] {
      if (!panoramaUploaded) {
        scene_->uploadPanorama(panorama_);
        panoramaUploaded = true;
      }
      const capture::Frame* camera = set.frame(splitCamera_);
      if (output.view->view() == ViewKind::kSplit && !cameraUploaded && camera != nullptr) {
        scene_->uploadCamera(camera->image);
        cameraUploaded = true;
      }
      output.view->draw(std::chrono::duration<double>(streamTime).count());
      output.pendingTime = streamTime;
    });
  }
  timed(Stage::kRender, since);
}

void Pipeline::deliverSurround() {
  for (auto& output : outputs_) {
    if (!output.view || !output.view->pending()) continue;
    guarded(output, [&] {
      auto since = std::chrono::steady_clock::now();
      const cv::Mat& picture = output.view->collect();
      timed(Stage::kReadBack, since);
      output.sink->consume(picture, output.pendingTime);
      timed(Stage::kOutput, since);
    });
  }
}

void Pipeline::finish(RunSummary& summary) {
  for (auto& camera : cameras_) camera->stop();
  deliverSurround();
  bool panoramaUploaded = false;
  for (auto& output : outputs_) {
    guarded(output, [&] {
      cv::Mat last;  // the picture of the last frame set, for sinks that write it at the end
      if (firstTimestamp_ && output.view) {
        if (!panoramaUploaded) scene_->uploadPanorama(panorama_);
        panoramaUploaded = true;
        output.view->draw(std::chrono::duration<double>(lastStreamTime_).count());
        last = output.view->collect();
      } else if (firstTimestamp_) {
        last = imageOf(output.stream);
      }
      output.sink->finish(last, lastStreamTime_);
      summary.outputs.push_back(output.sink->describe());
    });
  }
  for (auto& recorder : recorders_) {
    if (!recorder) continue;
    try {
      recorder->finish();
      summary.outputs.push_back(recorder->describe());
    } catch (const std::exception& e) {
      spdlog::error("recording failed to finish: {}", e.what());
      ++failedSinks_;
    }
  }
  summary.failedOutputs = failedSinks_;
  summary.sync = synchronizer_.stats();
  summary.stageTime = stageTime_;
  summary.healthChanges = healthChanges_;
  if (gl_) summary.renderer = gl_->description();
  for (const auto& camera : cameras_) {
    summary.cameraNames.push_back(camera->name());
    summary.cameras.push_back(camera->stats());
  }
}

}  // namespace surroundd::daemon
