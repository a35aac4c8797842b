#include "daemon/config/config_sections.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <optional>

#include "daemon/config/logging.hpp"
#include "daemon/config/view_rules.hpp"

namespace surroundd::daemon {
namespace {

constexpr const auto& kViews = render::kViewNames;

constexpr std::array<std::pair<std::string_view, GuidelineMode>, 3> kGuidelineModes{{
    {"reverse", GuidelineMode::kReverse},
    {"always", GuidelineMode::kAlways},
    {"off", GuidelineMode::kOff},
}};

// "#rrggbb" as RGB 0..1; none for anything else.
std::optional<cv::Vec3f> hexColour(const std::string& text) {
  if (text.size() != 7 || text[0] != '#') return std::nullopt;
  cv::Vec3f colour;
  for (std::size_t c = 0; c < 3; ++c) {
    unsigned value = 0;
    const char* first = text.data() + 1 + 2 * c;
    const auto [end, error] = std::from_chars(first, first + 2, value, 16);
    if (error != std::errc() || end != first + 2) return std::nullopt;
    colour[static_cast<int>(c)] = static_cast<float>(value) / 255.0F;
  }
  return colour;
}

void readGuidelineMarkers(YamlObject& section, RenderConfig& c) {
  const auto markers = section.numbers("guideline_markers_m", 0, 8);
  if (!markers) return;
  for (std::size_t m = 0; m < markers->size(); ++m) {
    const double distance = (*markers)[m];
    if (distance <= 0 || distance > 20 || (m > 0 && distance <= (*markers)[m - 1])) {
      section.error("guideline_markers_m",
                    fmt::format("expected up to 8 distances in 0..20 m, ascending, got {:g} at {}",
                                distance, m));
      return;
    }
  }
  c.guide.markersM = *markers;
}

// The path's colour, then one for each marker (after guideline_markers_m, which the table reads
// first).
void readGuidelineColours(YamlObject& section, RenderConfig& c) {
  const auto texts = section.strings("guideline_colours", 1, 9);
  if (!texts) return;
  if (texts->size() != c.guide.markersM.size() + 1) {
    section.error("guideline_colours",
                  fmt::format("expected {} colours (the paths', then one per marker of "
                              "guideline_markers_m), got {}",
                              c.guide.markersM.size() + 1, texts->size()));
    return;
  }
  std::vector<cv::Vec3f> colours;
  for (const std::string& text : *texts) {
    const auto colour = hexColour(text);
    // Black is where a gathered view shows no guideline (SurroundView::guidelineLayer).
    if (!colour || *colour == cv::Vec3f()) {
      section.error("guideline_colours",
                    fmt::format("expected colours as \"#rrggbb\", not black, got '{}'", text));
      return;
    }
    colours.push_back(*colour);
  }
  c.guide.pathColour = colours.front();
  c.guide.markerColours.assign(colours.begin() + 1, colours.end());
}

// The message's words and the reference's: one rule.
constexpr std::string_view kGainRangeRule = "0 < low <= 1 <= high <= 16";

void readGainRange(YamlObject& section, ColourCorrectionConfig& c) {
  const auto range = section.numbers("gain_range", {2});
  if (!range) return;
  const double low = (*range)[0];
  const double high = (*range)[1];
  if (low <= 0 || low > 1 || high < 1 || high > 16) {
    section.error("gain_range", fmt::format("expected [low, high] with {}, got [{:g}, {:g}]",
                                            kGainRangeRule, low, high));
    return;
  }
  c.poisson.minGain = low;
  c.poisson.maxGain = high;
}

bool sameGainRange(const ColourCorrectionConfig& a, const ColourCorrectionConfig& b) {
  return a.poisson.minGain == b.poisson.minGain && a.poisson.maxGain == b.poisson.maxGain;
}

void readView(YamlObject& item, OutputConfig& o) {
  if (!item.has("view")) return;
  if (o.stream != OutputStream::kSurround) {
    item.error("view", "only a surround output has a view");
    return;
  }
  o.view = item.choice("view", ViewKind::kOrbit,
                       std::span<const std::pair<std::string_view, ViewKind>>(kViews));
}

std::vector<std::string> viewNames() {
  std::vector<std::string> names;
  names.reserve(kViews.size());
  for (const auto& view : kViews) names.emplace_back(view.first);
  return names;
}

}  // namespace

double bowlRimRadiusM(const MeshConfig& mesh) { return 2 * mesh.bowlFloorRadiusM; }
double bowlRimHeightM(const MeshConfig& mesh) {
  return std::clamp(0.3 * (mesh.bowlRadiusM - mesh.bowlFloorRadiusM), 0.1, 50.0);
}

const ConfigKeys<Config>& loggingKeys() {
  using Key = ConfigKey<Config>;
  static const ConfigKeys<Config> kKeys{
      Key::choice("level", &Config::logLevel, kLogLevels,
                  "logs this level and above (--log-level overrides)"),
  };
  return kKeys;
}

const ConfigKeys<CaptureConfig>& captureKeys() {
  using Key = ConfigKey<CaptureConfig>;
  using capture::Pacing;
  using LatestWins = CaptureConfig::LatestWins;
  const auto recovery = [](auto member) { return nested(&CaptureConfig::recovery, member); };
  static const ConfigKeys<CaptureConfig> kKeys{
      Key::choice(
          "pacing", &CaptureConfig::pacing,
          {{"realtime", Pacing::kRealtime}, {"as_fast_as_possible", Pacing::kAsFastAsPossible}},
          "the pace of a replay (--pacing overrides)"),
      Key::number("sync_tolerance_ms", &CaptureConfig::syncToleranceMs,
                  {0.0, 1000.0, false, "milliseconds"},
                  "frames further apart than this are not one set"),
      Key::integer("queue_frames", &CaptureConfig::queueFrames, 1, 64,
                   "frames buffered per camera"),
      Key::number("late_after_ms", &CaptureConfig::lateAfterMs,
                  {1.0, 10000.0, false, "milliseconds"},
                  "live cameras: a frame set waits this long for a late camera, then goes "
                  "without it"),
      Key::choice("latest_wins", &CaptureConfig::latestWins,
                  {{"auto", LatestWins::kAuto},
                   {"always", LatestWins::kAlways},
                   {"never", LatestWins::kNever}},
                  "skip to the newest frame set when every camera has a newer frame waiting"),
      Key::integer("preload_max_mb", &CaptureConfig::preloadMaxMb, 1, 1 << 20,
                   "memory (MiB, 2^20 bytes) the frames of every preloaded camera "
                   "(source.preload) may take together"),
      Key::milliseconds("reopen_backoff_ms", recovery(&capture::RecoverySettings::firstBackoff), 1,
                        60'000, "the first wait before a lost camera is reopened"),
      Key::milliseconds("reopen_backoff_max_ms", recovery(&capture::RecoverySettings::maxBackoff),
                        1, 600'000, "the wait doubles after each failed try up to this"),
      Key::integer("give_up_after_faults", recovery(&capture::RecoverySettings::giveUpAfterFaults),
                   0, 1'000'000'000, "faults in a row without a frame that end the camera"),
      Key::seconds("fault_log_interval_s", recovery(&capture::RecoverySettings::logInterval),
                   {0.0, 3600.0, false, "seconds"},
                   "the first fault is logged, then one line at most this often that counts "
                   "the others"),
  };
  return kKeys;
}

const ConfigKeys<PipelineConfig>& pipelineKeys() {
  using Key = ConfigKey<PipelineConfig>;
  static const ConfigKeys<PipelineConfig> kKeys{
      Key::integer("threads", &PipelineConfig::threads, 0, 256,
                   "workers for the per-frame stages, counting the pipeline's own thread"),
  };
  return kKeys;
}

const ConfigKeys<ProcessingConfig>& processingKeys() {
  using Key = ConfigKey<ProcessingConfig>;
  static constexpr std::array<std::pair<std::string_view, ProcessingBackend>, 3> kBackends{{
      {"auto", ProcessingBackend::kAuto},
      {"cpu", ProcessingBackend::kCpu},
      {"gpu", ProcessingBackend::kGpu},
  }};
  static const ConfigKeys<ProcessingConfig> kKeys{
      Key::choice("backend", &ProcessingConfig::backend, kBackends,
                  "where the panorama is stitched and colour-corrected for the surround views: "
                  "cpu, gpu (OpenGL ES, from the camera frames as textures) or auto (gpu on a "
                  "hardware renderer, cpu on a software one)"),
  };
  return kKeys;
}

const ConfigKeys<PanoramaConfig>& panoramaKeys() {
  using Key = ConfigKey<PanoramaConfig>;
  const NumberRange elevation{-90.0, 90.0, false, "degrees"};
  static const ConfigKeys<PanoramaConfig> kKeys{
      Key::integer("width_px", &PanoramaConfig::widthPx, 64, 16384, "azimuth -180..180 degrees"),
      Key::integer("height_px", &PanoramaConfig::heightPx, 32, 8192, "elevation top..bottom"),
      Key::number("elevation_top_deg", &PanoramaConfig::elevationTopDeg, elevation,
                  "elevation of the first row"),
      Key::number("elevation_bottom_deg", &PanoramaConfig::elevationBottomDeg, elevation,
                  "elevation of the last row"),
      Key::choice("projection", &PanoramaConfig::projection,
                  {{"sphere", PanoramaProjection::kSphere}, {"bowl", PanoramaProjection::kBowl}},
                  "the surface each panorama ray meets"),
      Key::number("feather_deg", &PanoramaConfig::featherDeg, {0.0, 45.0, false, "degrees"},
                  "blend width across a seam"),
      Key::optionalPath("cache_dir", &PanoramaConfig::cacheDir,
                        "where built look-up tables are kept"),
  };
  return kKeys;
}

const ConfigKeys<ColourCorrectionConfig>& colourKeys() {
  using Key = ConfigKey<ColourCorrectionConfig>;
  using Settings = processing::ColourCorrectionSettings;
  const auto poisson = [](auto member) { return nested(&ColourCorrectionConfig::poisson, member); };
  static const ConfigKeys<ColourCorrectionConfig> kKeys{
      Key::choice("method", &ColourCorrectionConfig::method,
                  {{"none", ColourMethod::kNone},
                   {"gain", ColourMethod::kGain},
                   {"poisson", ColourMethod::kPoisson}},
                  "how the cameras' colours are matched"),
      Key::number("scale", poisson(&Settings::scale),
                  {0.0, 1.0, true, "fraction of the panorama size"},
                  "solve at this fraction of the panorama size"),
      Key::choice("field", poisson(&Settings::field),
                  {{"multiplicative", CorrectionField::kMultiplicative},
                   {"additive", CorrectionField::kAdditive}},
                  "how the field corrects a pixel"),
      Key::choice("solver", poisson(&Settings::solver),
                  {{"auto", PoissonSolverKind::kAuto},
                   {"cholmod", PoissonSolverKind::kCholmod},
                   {"iterative", PoissonSolverKind::kIterative}},
                  "how the field is solved"),
      Key::number("tolerance", poisson(&Settings::tolerance), {0.0, 0.5, true, "relative residual"},
                  "iterative solver: relative residual"),
      Key::number("temporal_smoothing", poisson(&Settings::temporalSmoothing),
                  {0.0, 0.99, false, "weight of the previous frame"},
                  "weight of the previous frame's seam data"),
      Key::custom("gain_range", "the correction's bounds as gains", readGainRange, sameGainRange,
                  {std::string(kGainRangeRule)}),
      Key::choice("seam_data", poisson(&Settings::groundSeams), {{"ground", true}, {"all", false}},
                  "which pixels the seams are measured on"),
      Key::flag("balance", poisson(&Settings::balance),
                "poisson: each camera's gains first, fitted over the seams' ground, taking every "
                "camera to the cameras' average; the field then corrects what is left"),
      Key::text("balance_reference", poisson(&Settings::balanceReference),
                "the camera whose colour the balance takes the others to (its gains stay 1); "
                "none: the cameras' average",
                Shown::kExample),
  };
  return kKeys;
}

const ConfigKeys<MeshConfig>& meshKeys() {
  using Key = ConfigKey<MeshConfig>;
  const NumberRange radius{0.5, 100.0, false, "metres"};
  static const ConfigKeys<MeshConfig> kKeys{
      Key::choice("model", &MeshConfig::model,
                  {{"flat", MeshModel::kFlat},
                   {"sphere360", MeshModel::kSphere360},
                   {"bowl", MeshModel::kBowl}},
                  "the surface's shape"),
      Key::number("flat_radius_m", &MeshConfig::flatRadiusM, radius, "flat: the disk's radius"),
      Key::number("sphere_radius_m", &MeshConfig::sphereRadiusM, radius,
                  "sphere360: the cropped sphere's radius"),
      // Its default follows the top view (the loader sets it before the walk).
      Key::number("bowl_floor_radius_m", &MeshConfig::bowlFloorRadiusM, radius,
                  "bowl: flat floor out to here", Shown::kExample),
      Key::derivedNumber("bowl_radius_m", &MeshConfig::bowlRadiusM, bowlRimRadiusM, radius,
                         "then the wall curves up (a parabola) to this radius"),
      Key::derivedNumber("bowl_height_m", &MeshConfig::bowlHeightM, bowlRimHeightM,
                         {0.1, 50.0, false, "metres"}, "and this height at the rim"),
      Key::integer("rings", &MeshConfig::rings, 2, 1024, "radial tessellation"),
      Key::integer("segments", &MeshConfig::segments, 8, 4096, "tessellation around the vehicle"),
  };
  return kKeys;
}

const ConfigKeys<RenderConfig>& renderKeys() {
  using Key = ConfigKey<RenderConfig>;
  using render::EglPlatform;
  using render::ViewSettings;
  const auto views = [](auto member) { return nested(&RenderConfig::views, member); };
  const NumberRange distance{0.5, 100.0, false, "metres"};
  // The eye's distances follow the vehicle (the loader sets them before the walk).
  const Shown followsVehicle = Shown::kExample;
  static const ConfigKeys<RenderConfig> kKeys{
      Key::choice("view", &RenderConfig::view, kViews, "of surround outputs that name none"),
      Key::integer("width_px", &RenderConfig::widthPx, 64, 7680,
                   "width of surround and mosaic outputs"),
      Key::integer("height_px", &RenderConfig::heightPx, 64, 4320,
                   "height of surround and mosaic outputs"),
      Key::choice("platform", &RenderConfig::platform,
                  {{"auto", EglPlatform::kAuto},
                   {"device", EglPlatform::kDevice},
                   {"surfaceless", EglPlatform::kSurfaceless},
                   {"default", EglPlatform::kDefault}},
                  "the EGL platform"),
      Key::number("top_range_m", views(&ViewSettings::topRangeM), distance,
                  "top view: the shorter side of the picture spans 2 x this on the ground",
                  followsVehicle),
      Key::number("top_height_m", views(&ViewSettings::topHeightM), distance,
                  "top view: eye height", followsVehicle),
      Key::number("orbit_radius_m", views(&ViewSettings::orbitRadiusM), distance,
                  "orbit: distance of the eye from the car's vertical axis", followsVehicle),
      Key::number("orbit_height_m", views(&ViewSettings::orbitHeightM), distance,
                  "orbit: the eye's height", followsVehicle),
      Key::number("orbit_period_s", views(&ViewSettings::orbitPeriodS),
                  {0.0, 3600.0, false, "seconds"},
                  "orbit: one turn in this much stream time; 0: the eye stays where it starts"),
      Key::number("orbit_start_deg", views(&ViewSettings::orbitStartDeg),
                  {-180.0, 180.0, false, "degrees"},
                  "orbit: the eye's azimuth at stream time 0, from straight ahead, positive to "
                  "the left; 180: behind the car"),
      Key::number("orbit_fov_deg", views(&ViewSettings::orbitFovDeg),
                  {10.0, 150.0, false, "degrees"}, "orbit: vertical field of view"),
      Key::number("strip_top_deg", views(&ViewSettings::stripTopDeg),
                  {-60.0, 60.0, false, "degrees"}, "360: elevation at the top of each strip"),
      Key::number("transition_s", views(&ViewSettings::transitionS), {0.0, 5.0, false, "seconds"},
                  "a switch of view moves the eye there (top and orbit) or fades the pictures "
                  "(the others) over this much stream time; 0: it cuts"),
      Key::text("split_camera", &RenderConfig::splitCamera, "the camera shown in the split view",
                Shown::kExample),
      Key::flag("view_lut", &RenderConfig::viewLut,
                "views that do not move (top, 360, and orbit and split with orbit_period_s 0) "
                "gathered from the camera frames through a look-up table of their own, not drawn "
                "by OpenGL"),
      Key::choice("guidelines", &RenderConfig::guidelines, kGuidelineModes,
                  "the wheels' predicted paths and distance markers on the ground, from the "
                  "steering angle (vehicle_signals): in reverse gear (behind the car), always "
                  "(ahead of it in the other gears too) or off"),
      Key::number("guideline_length_m",
                  nested(&RenderConfig::guide, &render::GuidelineSettings::lengthM),
                  {0.5, 20.0, false, "metres"}, "how far past the bumper the paths reach"),
      Key::custom(
          "guideline_markers_m", "distance markers across the paths, metres past the bumper",
          readGuidelineMarkers,
          [](const RenderConfig& a, const RenderConfig& b) {
            return a.guide.markersM == b.guide.markersM;
          },
          {}, Shown::kDefault),
      Key::custom(
          "guideline_colours", "the paths' colour, then one per marker, as \"#rrggbb\" (not black)",
          readGuidelineColours,
          [](const RenderConfig& a, const RenderConfig& b) {
            return a.guide.pathColour == b.guide.pathColour &&
                   a.guide.markerColours == b.guide.markerColours;
          },
          {}, Shown::kDefault),
  };
  return kKeys;
}

const ConfigKeys<ControlConfig>& controlKeys() {
  using Key = ConfigKey<ControlConfig>;
  static const ConfigKeys<ControlConfig> kKeys{
      Key::requiredPath("socket", &ControlConfig::socket, "surroundctl's socket"),
  };
  return kKeys;
}

const ConfigKeys<OutputConfig>& outputKeys() {
  using Key = ConfigKey<OutputConfig>;
  static const ConfigKeys<OutputConfig> kKeys{
      Key::choice("stream", &OutputConfig::stream,
                  {{"mosaic", OutputStream::kMosaic},
                   {"panorama", OutputStream::kPanorama},
                   {"surround", OutputStream::kSurround}},
                  "what it shows"),
      Key::custom(
          "view", "surround only: the view it starts with", readView,
          [](const OutputConfig& a, const OutputConfig& b) { return a.view == b.view; },
          viewNames(), Shown::kExample),
  };
  return kKeys;
}

const ConfigKeys<CalibrationWatchConfig>& calibrationWatchKeys() {
  using Key = ConfigKey<CalibrationWatchConfig>;
  static const ConfigKeys<CalibrationWatchConfig> kKeys{
      Key::number("interval_s", &CalibrationWatchConfig::intervalS, {0.0, 3600.0, false, "seconds"},
                  "how often (stream time) the ground under each seam is compared between its "
                  "two cameras; 0: never"),
      Key::number("threshold_cm", &CalibrationWatchConfig::thresholdCm,
                  {0.5, 100.0, false, "centimetres"},
                  "a seam whose cameras put the ground further apart is misaligned; a camera "
                  "whose every measured seam is, is calibration drifting"),
      Key::choice("correct", &CalibrationWatchConfig::correct,
                  {{"off", CalibrationWatchConfig::Correct::kOff},
                   {"suggest", CalibrationWatchConfig::Correct::kSuggest},
                   {"apply", CalibrationWatchConfig::Correct::kApply}},
                  "suggest: also work out, from the ground two cameras share while the car "
                  "drives, how each camera's mount would have to turn to bring its seams "
                  "together, and say it (status, metrics, log); surround-calibrate refine "
                  "--update-rig writes it. apply: also correct the panorama with it, once two "
                  "solutions in a row agree, and go back should the seams not come together"),
      Key::number("compare_every_s", &CalibrationWatchConfig::compareEveryS,
                  {0.1, 3600.0, false, "seconds"},
                  "with correct: suggest or apply, how often (stream time) a set's ground is "
                  "compared; each comparison costs tens of milliseconds on a thread of its own"),
  };
  return kKeys;
}

}  // namespace surroundd::daemon
