#include <algorithm>
#include <array>
#include <cmath>
#include <span>

#include <fmt/format.h>
#include <sys/un.h>

#include "daemon/config.hpp"
#include "daemon/logging.hpp"
#include "daemon/output_files.hpp"
#include "daemon/output_type.hpp"
#include "processing/colour/correction_domain.hpp"

namespace surroundd::daemon {
namespace {

// A Unix socket's path, as sockaddr_un holds it with its terminating NUL.
constexpr std::size_t kMaxSocketPathBytes = sizeof(sockaddr_un{}.sun_path) - 1;

void readRig(YamlObject& root, Config& config) {
  auto rig = root.object("rig");
  if (!rig) {
    root.errorHere(
        "missing key 'rig' (the cameras, inline as 'cameras:' or in a rig file as 'file:')");
    return;
  }
  if (rig->has("file") && rig->has("cameras")) {
    rig->errorHere("give either 'file' or 'cameras', not both");
  } else if (rig->has("file")) {
    if (const auto file = rig->existingFile("file")) {
      try {
        auto loaded = loadRig(*file);
        config.cameras = std::move(loaded.cameras);
        config.vehicle = loaded.vehicle;
      } catch (const ConfigError& e) {
        // The rig file's own messages already name it, its lines and keys.
        for (const auto& message : e.messages()) rig->diagnostics().add(message);
      }
    }
  } else {
    config.cameras = readRigCameras(*rig);
  }
  rig->finish();
  for (const auto& camera : config.cameras) {
    if (!camera.source && !camera.live()) {
      rig->errorHere(fmt::format("camera '{}' has no 'source' (surroundd needs one per camera)",
                                 camera.calibration.name));
    }
  }
  // Live devices and files run on different clocks; their frames could never be matched.
  const auto live =
      std::ranges::count_if(config.cameras, [](const RigCamera& c) { return c.live(); });
  if (live > 0 && live < static_cast<std::ptrdiff_t>(config.cameras.size())) {
    rig->errorHere(
        "mixes live devices and files: the cameras of a rig are either all live or all replayed");
  }
}

// H.264 in 4:2:0 needs even sizes; checked here so that no encoder fails at run time.
void requireEven(YamlObject& section, std::string_view key, int value) {
  if (value % 2 != 0) section.error(key, fmt::format("expected an even number, got {}", value));
}

void readPipeline(YamlObject& section, PipelineConfig& p) {
  p.threads = section.integer("threads", p.threads, 0, 256);
  section.finish();
}

void readCapture(YamlObject& section, CaptureConfig& c) {
  c.pacing = section.choice("pacing", c.pacing,
                            {{"realtime", capture::Pacing::kRealtime},
                             {"as_fast_as_possible", capture::Pacing::kAsFastAsPossible}});
  c.syncToleranceMs =
      section.number("sync_tolerance_ms", c.syncToleranceMs, {0.0, 1000.0, false, "milliseconds"});
  c.queueFrames = section.integer("queue_frames", c.queueFrames, 1, 64);
  c.lateAfterMs =
      section.number("late_after_ms", c.lateAfterMs, {1.0, 10000.0, false, "milliseconds"});
  using LatestWins = CaptureConfig::LatestWins;
  c.latestWins = section.choice("latest_wins", c.latestWins,
                                {{"auto", LatestWins::kAuto},
                                 {"always", LatestWins::kAlways},
                                 {"never", LatestWins::kNever}});
  c.preloadMaxMb = section.integer("preload_max_mb", c.preloadMaxMb, 1, 1 << 20);
  auto& r = c.recovery;
  r.firstBackoff = std::chrono::milliseconds(
      section.integer("reopen_backoff_ms", static_cast<int>(r.firstBackoff.count()), 1, 60'000));
  r.maxBackoff = std::chrono::milliseconds(
      section.integer("reopen_backoff_max_ms", static_cast<int>(r.maxBackoff.count()), 1, 600'000));
  if (r.maxBackoff < r.firstBackoff) {
    section.error("reopen_backoff_max_ms",
                  fmt::format("expected at least reopen_backoff_ms ({}), got {}",
                              r.firstBackoff.count(), r.maxBackoff.count()));
  }
  r.giveUpAfterFaults =
      section.integer("give_up_after_faults", r.giveUpAfterFaults, 0, 1'000'000'000);
  r.logInterval = std::chrono::milliseconds(
      std::lround(1000 * section.number("fault_log_interval_s",
                                        static_cast<double>(r.logInterval.count()) / 1000,
                                        {0.0, 3600.0, false, "seconds"})));
  section.finish();
}

void readPanorama(YamlObject& section, PanoramaConfig& p) {
  p.widthPx = section.integer("width_px", p.widthPx, 64, 16384);
  p.heightPx = section.integer("height_px", p.heightPx, 32, 8192);
  requireEven(section, "width_px", p.widthPx);
  requireEven(section, "height_px", p.heightPx);
  p.elevationTopDeg =
      section.number("elevation_top_deg", p.elevationTopDeg, {-90.0, 90.0, false, "degrees"});
  p.elevationBottomDeg =
      section.number("elevation_bottom_deg", p.elevationBottomDeg, {-90.0, 90.0, false, "degrees"});
  if (p.elevationBottomDeg >= p.elevationTopDeg) {
    section.error("elevation_bottom_deg",
                  fmt::format("expected less than elevation_top_deg ({:g}), got {:g}",
                              p.elevationTopDeg, p.elevationBottomDeg));
  }
  p.projection = section.choice(
      "projection", p.projection,
      {{"sphere", PanoramaProjection::kSphere}, {"bowl", PanoramaProjection::kBowl}});
  p.featherDeg = section.number("feather_deg", p.featherDeg, {0.0, 45.0, false, "degrees"});
  if (section.has("cache_dir")) p.cacheDir = section.outputPath("cache_dir").value_or("");
  section.finish();
}

void readColour(YamlObject& section, ColourCorrectionConfig& c) {
  c.method = section.choice("method", c.method,
                            {{"none", ColourMethod::kNone},
                             {"gain", ColourMethod::kGain},
                             {"poisson", ColourMethod::kPoisson}});
  auto& p = c.poisson;
  p.scale = section.number("scale", p.scale, {0.0, 1.0, true, "fraction of the panorama size"});
  p.field = section.choice("field", p.field,
                           {{"multiplicative", CorrectionField::kMultiplicative},
                            {"additive", CorrectionField::kAdditive}});
  p.solver = section.choice("solver", p.solver,
                            {{"auto", PoissonSolverKind::kAuto},
                             {"cholmod", PoissonSolverKind::kCholmod},
                             {"iterative", PoissonSolverKind::kIterative}});
  p.tolerance = section.number("tolerance", p.tolerance, {0.0, 0.5, true, "relative residual"});
  p.temporalSmoothing = section.number("temporal_smoothing", p.temporalSmoothing,
                                       {0.0, 0.99, false, "weight of the previous frame"});
  if (const auto range = section.numbers("gain_range", {2})) {
    if ((*range)[0] <= 0 || (*range)[0] > 1 || (*range)[1] < 1 || (*range)[1] > 16) {
      section.error("gain_range",
                    fmt::format("expected [low, high] with 0 < low <= 1 <= high <= 16, got [{:g}, "
                                "{:g}]",
                                (*range)[0], (*range)[1]));
    } else {
      p.minGain = (*range)[0];
      p.maxGain = (*range)[1];
    }
  }
  p.groundSeams = section.choice("seam_data", p.groundSeams, {{"ground", true}, {"all", false}});
  section.finish();
}

// The wall rises over as much again as the floor's radius (far enough for a gentle slope), to a
// height in proportion.
double bowlRimRadius(double floorRadiusM) { return 2 * floorRadiusM; }
double bowlRimHeight(double floorRadiusM, double rimRadiusM) {
  return std::clamp(0.3 * (rimRadiusM - floorRadiusM), 0.1, 50.0);
}

void readMesh(YamlObject& section, MeshConfig& m) {
  const NumberRange radius{0.5, 100.0, false, "metres"};
  m.model = section.choice("model", m.model,
                           {{"flat", MeshModel::kFlat},
                            {"sphere360", MeshModel::kSphere360},
                            {"bowl", MeshModel::kBowl}});
  m.flatRadiusM = section.number("flat_radius_m", m.flatRadiusM, radius);
  m.sphereRadiusM = section.number("sphere_radius_m", m.sphereRadiusM, radius);
  m.bowlFloorRadiusM = section.number("bowl_floor_radius_m", m.bowlFloorRadiusM, radius);
  m.bowlRadiusM = section.number("bowl_radius_m", bowlRimRadius(m.bowlFloorRadiusM), radius);
  m.bowlHeightM = section.number("bowl_height_m", bowlRimHeight(m.bowlFloorRadiusM, m.bowlRadiusM),
                                 {0.1, 50.0, false, "metres"});
  if (m.bowlFloorRadiusM >= m.bowlRadiusM) {
    section.error("bowl_floor_radius_m",
                  fmt::format("expected less than bowl_radius_m ({:g}), got {:g}", m.bowlRadiusM,
                              m.bowlFloorRadiusM));
  }
  m.rings = section.integer("rings", m.rings, 2, 1024);
  m.segments = section.integer("segments", m.segments, 8, 4096);
  section.finish();
}

constexpr std::array<std::pair<std::string_view, ViewKind>, 4> kViews{{
    {"top", ViewKind::kTop},
    {"360", ViewKind::kPanorama360},
    {"orbit", ViewKind::kOrbit},
    {"split", ViewKind::kSplit},
}};

void readRender(YamlObject& section, RenderConfig& r) {
  r.view = section.choice("view", r.view,
                          std::span<const std::pair<std::string_view, ViewKind>>(kViews));
  r.widthPx = section.integer("width_px", r.widthPx, 64, 7680);
  r.heightPx = section.integer("height_px", r.heightPx, 64, 4320);
  requireEven(section, "width_px", r.widthPx);
  requireEven(section, "height_px", r.heightPx);
  r.platform = section.choice("platform", r.platform,
                              {{"auto", render::EglPlatform::kAuto},
                               {"device", render::EglPlatform::kDevice},
                               {"surfaceless", render::EglPlatform::kSurfaceless},
                               {"default", render::EglPlatform::kDefault}});
  const NumberRange distance{0.5, 100.0, false, "metres"};
  auto& v = r.views;
  v.topRangeM = section.number("top_range_m", v.topRangeM, distance);
  v.topHeightM = section.number("top_height_m", v.topHeightM, distance);
  v.orbitRadiusM = section.number("orbit_radius_m", v.orbitRadiusM, distance);
  v.orbitHeightM = section.number("orbit_height_m", v.orbitHeightM, distance);
  v.orbitPeriodS =
      section.number("orbit_period_s", v.orbitPeriodS, {0.5, 3600.0, false, "seconds"});
  v.orbitFovDeg = section.number("orbit_fov_deg", v.orbitFovDeg, {10.0, 150.0, false, "degrees"});
  v.stripTopDeg = section.number("strip_top_deg", v.stripTopDeg, {-60.0, 60.0, false, "degrees"});
  r.splitCamera = section.string("split_camera", r.splitCamera);
  for (const auto* moved : {"car_length_m", "car_width_m", "car_height_m"}) {
    if (section.has(moved)) {
      section.error(moved,
                    "the car's size is the vehicle's now: vehicle.length_m, width_m, height_m");
    }
  }
  section.finish();
}

// The keys every output has (type, stream, view), then its type's own (output_type.hpp).
OutputConfig readOutput(YamlObject& item) {
  OutputConfig o;
  std::vector<std::pair<std::string_view, const OutputType*>> types;
  for (const std::string_view name : outputTypeNames())
    types.emplace_back(name, findOutputType(name));
  const OutputType* type = item.choice<const OutputType*>(
      "type", &outputTypeOf(o),
      std::span<const std::pair<std::string_view, const OutputType*>>(types));
  if (!item.has("type")) {
    std::string names;
    for (const auto& [name, t] : types)
      names += fmt::format("{}'{}'", names.empty() ? "" : " ", name);
    item.errorHere(fmt::format("missing key 'type' (one of {})", names));
  }
  o.kind = OutputKind(type->name);
  o.stream = item.choice("stream", o.stream,
                         {{"mosaic", OutputStream::kMosaic},
                          {"panorama", OutputStream::kPanorama},
                          {"surround", OutputStream::kSurround}});
  if (item.has("view")) {
    if (o.stream == OutputStream::kSurround) {
      o.view = item.choice("view", ViewKind::kOrbit,
                           std::span<const std::pair<std::string_view, ViewKind>>(kViews));
    } else {
      item.error("view", "only a surround output has a view");
    }
  }
  if (!type->leftOut.empty()) {
    // Its keys are not read: this build does not know them.
    item.error("type", fmt::format("this surroundd is built without '{}' outputs: {}", type->name,
                                   type->leftOut));
    return o;
  }
  type->readSettings(item, o);
  item.finish();
  return o;
}

}  // namespace

VehicleSizes vehicleSizes(const VehicleConfig& vehicle) {
  // Three times the body's reach frames a car as the familiar 8 m top view (4.5 m car: 8.0 m), a
  // 0.3 m robot as a 1.5 m room; the eyes keep their proportions to the range.
  const double range = std::max(1.5, 3.3 * vehicle.reachM());
  return {range, 1.75 * range, range, 0.5625 * range};
}

double topViewReachM(const RenderConfig& render) {
  const double longer = std::max(render.widthPx, render.heightPx);
  const double shorter = std::min(render.widthPx, render.heightPx);
  return render.views.topRangeM * std::hypot(1.0, longer / shorter);
}

namespace {

Config readConfig(const YAML::Node& document, const std::filesystem::path& file) {
  Diagnostics diag;
  Config config;
  config.file = file;
  YamlObject root(document, "", file, diag);
  readRig(root, config);
  const auto readSection = [&](std::string_view key, auto&& read) {
    if (auto section = root.object(key)) read(*section);
  };
  readSection("logging", [&](YamlObject& s) {
    config.logLevel = s.choice(
        "level", config.logLevel,
        std::span<const std::pair<std::string_view, spdlog::level::level_enum>>(kLogLevels));
    s.finish();
  });
  readSection("capture", [&](YamlObject& s) { readCapture(s, config.capture); });
  readSection("pipeline", [&](YamlObject& s) { readPipeline(s, config.pipeline); });
  readSection("panorama", [&](YamlObject& s) { readPanorama(s, config.panorama); });
  readSection("colour_correction", [&](YamlObject& s) { readColour(s, config.colour); });
  // The correction's blocks must tile the panorama (processing's rule, checked here first).
  const cv::Size panorama(config.panorama.widthPx, config.panorama.heightPx);
  if (!processing::correctionBlock(config.colour.poisson.scale, panorama)) {
    const auto message =
        fmt::format("colour_correction.scale {}",
                    processing::correctionBlockProblem(config.colour.poisson.scale, panorama));
    if (auto section = root.object("colour_correction")) {
      section->error("scale", message);
    } else {
      root.error("panorama", message);
    }
  }
  readSection("vehicle", [&](YamlObject& s) { config.vehicle = readVehicle(s); });
  const VehicleConfig vehicle = config.vehicle.value_or(VehicleConfig{});
  config.render.car = vehicle.car();
  // The render's size and views first: the bowl's default floor follows the top view.
  const VehicleSizes sizes = vehicleSizes(vehicle);
  config.render.views.topRangeM = sizes.topRangeM;
  config.render.views.topHeightM = sizes.topHeightM;
  config.render.views.orbitRadiusM = sizes.orbitRadiusM;
  config.render.views.orbitHeightM = sizes.orbitHeightM;
  readSection("render", [&](YamlObject& s) {
    readRender(s, config.render);
    const auto& split = config.render.splitCamera;
    if (!split.empty() && std::ranges::none_of(config.cameras, [&](const RigCamera& c) {
          return c.calibration.name == split;
        })) {
      s.error("split_camera", fmt::format("no camera is named '{}'", split));
    }
  });
  const double topReach = topViewReachM(config.render);
  config.mesh.bowlFloorRadiusM = topReach;
  config.mesh.bowlRadiusM = bowlRimRadius(topReach);
  config.mesh.bowlHeightM = bowlRimHeight(topReach, config.mesh.bowlRadiusM);
  readSection("mesh", [&](YamlObject& s) { readMesh(s, config.mesh); });
  for (const auto& camera : config.cameras) {
    if (auto warning = lensFieldCutWarning(camera.calibration)) {
      config.warnings.push_back(std::move(*warning));
    }
  }
  if (config.mesh.model == MeshModel::kBowl && config.mesh.bowlFloorRadiusM + 1e-9 < topReach) {
    config.warnings.push_back(fmt::format(
        "mesh.bowl_floor_radius_m {:g} is less than the {:g} m the top view shows from the "
        "vehicle's centre: straight lines on the ground bend where the bowl's wall begins",
        config.mesh.bowlFloorRadiusM, topReach));
  }
  readSection("control", [&](YamlObject& s) {
    config.control.socket = s.outputPath("socket").value_or("");
    if (config.control.socket.string().size() > kMaxSocketPathBytes) {
      s.error("socket", fmt::format("expected a path of at most {} bytes (a Unix socket's limit), "
                                    "got {} bytes",
                                    kMaxSocketPathBytes, config.control.socket.string().size()));
    }
    s.finish();
  });
  for (auto& item : root.objectList("outputs", 1, 32)) {
    auto output = readOutput(item);
    const OutputType& type = outputTypeOf(output);
    for (std::size_t earlier = 0; earlier < config.outputs.size(); ++earlier) {
      const OutputConfig& other = config.outputs[earlier];
      if (auto clash = outputFileClash(other, output)) {
        item.error("path", fmt::format("{} (outputs[{}] too)", *clash, earlier));
      }
      if (type.conflict && other.kind == output.kind) {
        if (const auto conflict = type.conflict(other, output)) {
          item.error(conflict->key, fmt::format("outputs[{}] {}", earlier, conflict->message));
        }
      }
    }
    config.outputs.push_back(std::move(output));
  }
  root.finish();
  diag.throwIfAny();
  return config;
}

}  // namespace

Config loadConfig(const std::filesystem::path& file) {
  return readConfig(parseYamlFile(file), file);
}

Config loadConfigText(const std::string& text, const std::filesystem::path& file) {
  return readConfig(parseYamlText(text, file), file);
}

}  // namespace surroundd::daemon
