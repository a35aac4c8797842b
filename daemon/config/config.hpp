#pragma once
// Everything surroundd is configured with: one YAML file, read and validated by loadConfig().
// A key's default is its field's initialiser here; its range, unit and doc are its row in its
// section's table (config_sections.cpp, an output type's keys, vehicleKeys()); the reference
// config, config/surroundd.reference.yaml, documents every key and is tested against both.
//
// The parts' settings are plain structs with units in their names; they are defined here until the
// part that consumes them exists (processing/ and render/ never see YAML).

#include <algorithm>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <spdlog/common.h>

#include "capture/file_source.hpp"
#include "capture/source_recovery.hpp"
#include "daemon/config/rig_yaml.hpp"
#include "daemon/config/vehicle_yaml.hpp"
#include "processing/colour/poisson_correction.hpp"
#include "processing/stitch/panorama_lut.hpp"
#include "processing/surround_mesh.hpp"
#include "render/egl_context.hpp"
#include "render/guidelines.hpp"
#include "render/view_camera.hpp"
#include "vehicle/can_signal_reader.hpp"
#include "vehicle/vehicle_signals.hpp"

namespace surroundd::daemon {

struct CaptureConfig {
  capture::Pacing pacing = capture::Pacing::kRealtime;
  double syncToleranceMs = 10.0;  // frames further apart than this are not one set
  int queueFrames = 4;        // frames buffered per camera between its thread and the synchronizer
  double lateAfterMs = 50.0;  // live: a set waits this long for a late camera, then goes without
  // Skip to the newest frame set when every camera has a newer frame waiting (and let an encoder
  // drop its oldest picture): auto = only with live cameras; always also for replays (to see a
  // replay as a live rig would show it), never keeps every set.
  enum class LatestWins { kAuto, kAlways, kNever } latestWins = LatestWins::kAuto;
  // The memory, in MiB (2^20 bytes), that the frames of every preloaded camera (`preload: true`)
  // may take together; a camera that would go past it is refused at start, naming it.
  int preloadMaxMb = 2048;
  // How every camera, whatever its kind, recovers from faults (capture/source_recovery.hpp):
  // reopening backoff, giving up, and how often repeated faults are logged.
  capture::RecoverySettings recovery;

  bool operator==(const CaptureConfig&) const = default;
};

struct PipelineConfig {
  int threads = 0;  // workers for the per-frame stages (stitch, ...), counting the pipeline thread;
                    // 0 = one per core

  bool operator==(const PipelineConfig&) const = default;
};

// Where each set's panorama is stitched and colour-corrected: on the CPU (processing/stitch/), on
// the GPU by OpenGL ES (render/gpu_stitcher.hpp), or auto: the GPU when the EGL renderer is a
// hardware one, the CPU on a software renderer (llvmpipe, softpipe), where the GPU path is slower.
enum class ProcessingBackend { kAuto, kCpu, kGpu };

struct ProcessingConfig {
  ProcessingBackend backend = ProcessingBackend::kAuto;

  bool operator==(const ProcessingConfig&) const = default;
};

using processing::PanoramaProjection;

struct PanoramaConfig {
  int widthPx = 2048;   // azimuth -180..180 degrees
  int heightPx = 1024;  // elevation top..bottom
  double elevationTopDeg = 30.0;
  double elevationBottomDeg = -60.0;
  PanoramaProjection projection = PanoramaProjection::kBowl;
  double featherDeg = 4.0;  // blend width across a seam
  // Where built LUTs are kept; empty: $STATE_DIRECTORY (systemd), else $XDG_CACHE_HOME/surroundd,
  // else ~/.cache/surroundd.
  std::filesystem::path cacheDir;

  bool operator==(const PanoramaConfig&) const = default;
};

enum class ColourMethod { kNone, kGain, kPoisson };
using processing::CorrectionField;
using processing::PoissonSolverKind;

struct ColourCorrectionConfig {
  ColourMethod method = ColourMethod::kPoisson;
  processing::ColourCorrectionSettings poisson;  // for method kPoisson

  bool operator==(const ColourCorrectionConfig&) const = default;
};

using processing::MeshModel;

// The bowl's floor and rim, the top view's range and the orbit's distance default to sizes that
// follow the vehicle (vehicleSizes()); these are the figures for the default car.
struct MeshConfig {
  MeshModel model = MeshModel::kBowl;
  double flatRadiusM = 9.0;       // flat disk
  double sphereRadiusM = 10.0;    // 360-horizontal cropped sphere
  double bowlFloorRadiusM = 5.0;  // bowl: flat floor, then the wall curves up
  double bowlRadiusM = 10.0;      // bowl: outer radius at the rim
  double bowlHeightM = 3.0;       // bowl: rim height above the ground
  int rings = 48;                 // radial tessellation
  int segments = 128;             // around the vehicle

  bool operator==(const MeshConfig&) const = default;
};

using render::ViewKind;

// When the guidelines are drawn: in reverse gear (behind the car), also in the other gears (ahead
// of it), or never.
enum class GuidelineMode { kOff, kReverse, kAlways };

struct RenderConfig {
  ViewKind view = ViewKind::kOrbit;  // of surround outputs that do not name their own
  int widthPx = 1280;                // the size of surround and mosaic outputs
  int heightPx = 720;
  render::EglPlatform platform = render::EglPlatform::kAuto;
  render::ViewSettings views;
  std::string splitCamera;  // the camera beside the 3D view in the split view; empty: the first
  bool viewLut = true;      // top and 360 views gathered from the frames through a view LUT
  GuidelineMode guidelines = GuidelineMode::kReverse;
  render::GuidelineSettings guide;

  bool operator==(const RenderConfig&) const = default;
};

// What an output shows: the labelled camera grid, the stitched panorama, or the rendered
// surround view.
enum class OutputStream { kMosaic, kPanorama, kSurround };

// An output's `type:`: the name of an output type in the registry (output_type.hpp), where each
// type registers its keys, its factory and what it takes from the pipeline. The built-in types are
// named here for code that writes configs; a type registered elsewhere is OutputKind{"its-name"}.
class OutputKind {
 public:
  constexpr explicit OutputKind(std::string_view name) : name_(name) {}
  constexpr std::string_view name() const { return name_; }
  bool operator==(const OutputKind& other) const { return name_ == other.name_; }

  static const OutputKind kVideo, kNetwork, kHttp, kRtsp, kWindow, kDisplay, kSnapshot;
  // Not a picture of the pipeline but the cameras' own streams (RigRecorder).
  static const OutputKind kRecording;

 private:
  std::string_view name_;  // a literal, or the registry's copy: lives as long as the program
};
inline constexpr OutputKind OutputKind::kVideo{"video"};
inline constexpr OutputKind OutputKind::kNetwork{"network"};
inline constexpr OutputKind OutputKind::kHttp{"http"};
inline constexpr OutputKind OutputKind::kRtsp{"rtsp"};
inline constexpr OutputKind OutputKind::kWindow{"window"};
inline constexpr OutputKind OutputKind::kDisplay{"display"};
inline constexpr OutputKind OutputKind::kSnapshot{"snapshot"};
inline constexpr OutputKind OutputKind::kRecording{"recording"};

// An output's own settings, those of its type (`type:`): the struct its type's key table reads
// (daemon/outputs/<type>/), kept as it is and compared by value. Copies share it (it is not
// changed once read). Empty: the type's defaults.
class OutputSettings {
 public:
  template <class Settings>
  explicit OutputSettings(Settings settings)
      : held_(std::make_shared<const Held<Settings>>(std::move(settings))) {}
  OutputSettings() = default;

  // The settings if they are a `Settings`, else null.
  template <class Settings>
  const Settings* get() const {
    const auto* held = dynamic_cast<const Held<Settings>*>(held_.get());
    return held != nullptr ? &held->settings : nullptr;
  }
  bool empty() const { return held_ == nullptr; }
  bool operator==(const OutputSettings& other) const {
    return held_ == other.held_ || (held_ && other.held_ && held_->equals(*other.held_));
  }

 private:
  struct Base {
    virtual ~Base() = default;
    virtual bool equals(const Base& other) const = 0;
  };
  template <class Settings>
  struct Held final : Base {
    explicit Held(Settings s) : settings(std::move(s)) {}
    bool equals(const Base& other) const override {
      const auto* same = dynamic_cast<const Held*>(&other);
      return same != nullptr && same->settings == settings;
    }
    Settings settings;
  };
  std::shared_ptr<const Base> held_;
};

// One entry of `outputs:`: the keys every output has; its type's own are in `settings`.
struct OutputConfig {
  OutputKind kind = OutputKind::kVideo;
  OutputStream stream = OutputStream::kMosaic;
  std::filesystem::path path;    // of the types that write files; parent folders are made at start
  std::optional<ViewKind> view;  // surround: the view it starts with; default render.view
  OutputSettings settings;
  // Set when opened: `path` as configured, where `path` is this run's own <stem>-N<ext>.
  std::filesystem::path family;

  bool operator==(const OutputConfig&) const = default;
};

// `output`'s settings as its type's `Settings`: the type's defaults where it holds none (an output
// written by code). Throws std::logic_error if it holds another type's.
template <class Settings>
const Settings& settingsOf(const OutputConfig& output) {
  static const Settings kDefaults{};
  if (output.settings.empty()) return kDefaults;
  if (const Settings* held = output.settings.get<Settings>()) return *held;
  throw std::logic_error("an output's settings are not those of its type");
}

struct ControlConfig {
  // The control socket (surroundctl); empty: defaultControlSocket(), and none if that is empty.
  std::filesystem::path socket;

  bool operator==(const ControlConfig&) const = default;
};

// A view the vehicle's signals bring up (vehicle_signals.view_rules): when every condition it
// names holds. Conditions on a signal that is unknown (never set, or stale) do not hold.
struct ViewRule {
  std::optional<vehicle::Gear> gear;
  std::optional<vehicle::Indicator> indicator;
  std::optional<double> speedBelowKmh;
  std::optional<double> speedAboveKmh;
  ViewKind view = ViewKind::kTop;

  bool operator==(const ViewRule&) const = default;
};

struct VehicleSignalsConfig {
  double staleAfterS = 1.0;         // a signal not renewed for this long reads as its safe default
  std::vector<ViewRule> viewRules;  // the first that holds wins
  std::optional<vehicle::CanSignalMapping> can;  // none: signals from the control socket alone

  bool operator==(const VehicleSignalsConfig&) const = default;
};

// The calibration-drift watch: how often it compares the ground under each seam between the
// seam's two cameras, and how far apart is too far.
struct CalibrationWatchConfig {
  double intervalS = 5;    // of stream time; 0: off
  double thresholdCm = 5;  // a seam whose cameras put the ground further apart is misaligned
  // Whether the watch also works out the mounts that would bring the seams together
  // (processing/calibration/mount_refinement.hpp), and says them (suggest), or also corrects the
  // panorama with them (apply).
  enum class Correct { kOff, kSuggest, kApply };
  Correct correct = Correct::kOff;
  double compareEveryS = 1;  // of stream time: how often a set's ground patches are compared

  bool operator==(const CalibrationWatchConfig&) const = default;
};

struct Config {
  std::filesystem::path file;
  spdlog::level::level_enum logLevel = spdlog::level::info;
  std::vector<RigCamera> cameras;
  // The rig file the cameras were read from (`rig: {file:}`, where the config found it); none for
  // cameras written inline.
  std::optional<std::filesystem::path> rigFile;
  // The config's `vehicle:`, else the rig file's; none: the default car is drawn and no camera is
  // masked.
  std::optional<VehicleConfig> vehicle;
  CaptureConfig capture;
  PipelineConfig pipeline;
  ProcessingConfig processing;
  PanoramaConfig panorama;
  ColourCorrectionConfig colour;
  MeshConfig mesh;
  RenderConfig render;
  ControlConfig control;
  VehicleSignalsConfig vehicleSignals;
  CalibrationWatchConfig calibrationWatch;
  std::vector<OutputConfig> outputs;
  // What is worth saying about a valid config (surroundd logs them at start, --check-config prints
  // them).
  std::vector<std::string> warnings;

  // The vehicle drawn and guided: `vehicle`, else the default car.
  processing::VehicleDimensions car() const { return vehicle.value_or(VehicleConfig{}); }
  // Whether an output shows `stream`.
  bool shows(OutputStream stream) const {
    return std::ranges::any_of(outputs, [&](const OutputConfig& o) { return o.stream == stream; });
  }
};

// Default sizes that follow the vehicle: a small robot in a room wants a closer look than a bus.
struct VehicleSizes {
  double topRangeM = 0, topHeightM = 0, orbitRadiusM = 0, orbitHeightM = 0;
};
VehicleSizes vehicleSizes(const VehicleConfig& vehicle);
// How far from the vehicle frame's origin the top view shows the ground (its picture's corners).
double topViewReachM(const RenderConfig& render);

// Reads and validates the whole file; throws ConfigError with one line per problem. Every camera
// must have a source.
Config loadConfig(const std::filesystem::path& file);
// The same for a config's text: `file` is where its relative paths start and what messages name
// (the fuzz test's entry, with no file to write).
Config loadConfigText(const std::string& text, const std::filesystem::path& file);

}  // namespace surroundd::daemon
