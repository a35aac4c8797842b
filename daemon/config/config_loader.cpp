#include <algorithm>
#include <array>
#include <cmath>
#include <span>

#include <fmt/format.h>
#include <sys/un.h>

#include "daemon/config/config.hpp"
#include "daemon/config/config_sections.hpp"
#include "daemon/config/logging.hpp"
#include "daemon/config/output_files.hpp"
#include "daemon/config/output_type.hpp"
#include "daemon/config/view_rules.hpp"
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
        config.rigFile = *file;
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
    if (!camera.source) {
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

void readCapture(YamlObject& section, CaptureConfig& c) {
  captureKeys().read(section, c);
  const auto& r = c.recovery;
  if (r.maxBackoff < r.firstBackoff) {
    section.error("reopen_backoff_max_ms",
                  fmt::format("expected at least reopen_backoff_ms ({}), got {}",
                              r.firstBackoff.count(), r.maxBackoff.count()));
  }
}

void readPanorama(YamlObject& section, PanoramaConfig& p) {
  panoramaKeys().read(section, p);
  requireEven(section, "width_px", p.widthPx);
  requireEven(section, "height_px", p.heightPx);
  if (p.elevationBottomDeg >= p.elevationTopDeg) {
    section.error("elevation_bottom_deg",
                  fmt::format("expected less than elevation_top_deg ({:g}), got {:g}",
                              p.elevationTopDeg, p.elevationBottomDeg));
  }
}

void readMesh(YamlObject& section, MeshConfig& m) {
  meshKeys().read(section, m);
  if (m.bowlFloorRadiusM >= m.bowlRadiusM) {
    section.error("bowl_floor_radius_m",
                  fmt::format("expected less than bowl_radius_m ({:g}), got {:g}", m.bowlRadiusM,
                              m.bowlFloorRadiusM));
  }
}

void readRender(YamlObject& section, RenderConfig& r) {
  renderKeys().read(section, r);
  requireEven(section, "width_px", r.widthPx);
  requireEven(section, "height_px", r.heightPx);
  for (const auto* moved : {"car_length_m", "car_width_m", "car_height_m"}) {
    if (section.has(moved)) {
      section.error(moved,
                    "the car's size is the vehicle's now: vehicle.length_m, width_m, height_m");
    }
  }
}

void readControl(YamlObject& section, ControlConfig& c) {
  controlKeys().read(section, c);
  if (c.socket.string().size() > kMaxSocketPathBytes) {
    section.error("socket", fmt::format("expected a path of at most {} bytes (a Unix socket's "
                                        "limit), got {} bytes",
                                        kMaxSocketPathBytes, c.socket.string().size()));
  }
}

// The output type an entry's `type:` names (the video type, reported, when it names none).
const OutputType& readOutputType(YamlObject& item) {
  std::vector<std::pair<std::string_view, const OutputType*>> types;
  for (const std::string_view name : outputTypeNames())
    types.emplace_back(name, findOutputType(name));
  if (types.empty()) {
    // A program's mistake, not the config's.
    throw std::logic_error(
        "no output types are registered: a program that reads configs calls "
        "registerBuiltInOutputTypes() (daemon/outputs/built_in_outputs.hpp) first");
  }
  const OutputType* type = item.choice<const OutputType*>(
      "type", &outputTypeOf(OutputConfig{}),
      std::span<const std::pair<std::string_view, const OutputType*>>(types));
  if (!item.has("type")) {
    std::string names;
    for (const auto& [name, t] : types)
      names += fmt::format("{}'{}'", names.empty() ? "" : " ", name);
    item.errorHere(fmt::format("missing key 'type' (one of {})", names));
  }
  return *type;
}

// The keys every output has (type, stream, view), then its type's own (output_type.hpp).
OutputConfig readOutput(YamlObject& item) {
  OutputConfig o;
  const OutputType& type = readOutputType(item);
  o.kind = OutputKind(type.name);
  outputKeys().read(item, o);
  if (!type.leftOut.empty()) {
    // Its keys are not read: this build does not know them.
    item.error("type", fmt::format("this surroundd is built without '{}' outputs: {}", type.name,
                                   type.leftOut));
    return o;
  }
  readOutputPath(item, type, o);
  o.settings = type.readSettings(item, o);
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

// A section read by its table and named checks (`read`), then its unknown keys reported.
template <class Read>
void readSection(YamlObject& root, std::string_view key, Read&& read) {
  if (auto section = root.object(key)) {
    read(*section);
    section->finish();
  }
}

// A key that names a camera (none: empty) names one of the rig's.
void checkNamesACamera(YamlObject& section, std::string_view key, const std::string& name,
                       const Config& config) {
  if (!name.empty() && std::ranges::none_of(config.cameras, [&](const RigCamera& c) {
        return c.calibration.name == name;
      })) {
    section.error(key, fmt::format("no camera is named '{}'", name));
  }
}

void checkBalanceReference(YamlObject& section, const Config& config) {
  const auto& poisson = config.colour.poisson;
  checkNamesACamera(section, "balance_reference", poisson.balanceReference, config);
  if (!poisson.balanceReference.empty() && !poisson.balance) {
    section.error("balance_reference", "is the balance's: it needs balance: true");
  }
}

// The correction's blocks must tile the panorama: a rule across two sections, told at the scale
// where the config gives one.
void checkCorrectionScale(YamlObject& root, const Config& config) {
  const cv::Size panorama(config.panorama.widthPx, config.panorama.heightPx);
  const double scale = config.colour.poisson.scale;
  if (processing::correctionBlock(scale, panorama)) return;
  const auto message = fmt::format("colour_correction.scale {}",
                                   processing::correctionBlockProblem(scale, panorama));
  if (auto section = root.object("colour_correction")) {
    section->error("scale", message);
  } else {
    root.error("panorama", message);
  }
}

// The render's views' defaults follow the vehicle.
void renderDefaults(Config& config) {
  const VehicleSizes sizes = vehicleSizes(config.vehicle.value_or(VehicleConfig{}));
  auto& views = config.render.views;
  views.topRangeM = sizes.topRangeM;
  views.topHeightM = sizes.topHeightM;
  views.orbitRadiusM = sizes.orbitRadiusM;
  views.orbitHeightM = sizes.orbitHeightM;
}

// After the render: the bowl's default floor reaches as far as the top view shows.
void meshDefaults(Config& config) {
  auto& mesh = config.mesh;
  mesh.bowlFloorRadiusM = topViewReachM(config.render);
  mesh.bowlRadiusM = bowlRimRadiusM(mesh);
  mesh.bowlHeightM = bowlRimHeightM(mesh);
}

void addWarnings(Config& config) {
  for (const auto& camera : config.cameras) {
    if (auto warning = lensFieldCutWarning(camera.calibration)) {
      config.warnings.push_back(std::move(*warning));
    }
  }
  const double topReach = topViewReachM(config.render);
  if (config.mesh.model == MeshModel::kBowl && config.mesh.bowlFloorRadiusM + 1e-9 < topReach) {
    config.warnings.push_back(fmt::format(
        "mesh.bowl_floor_radius_m {:g} is less than the {:g} m the top view shows from the "
        "vehicle's centre: straight lines on the ground bend where the bowl's wall begins",
        config.mesh.bowlFloorRadiusM, topReach));
  }
}

// Each output, and what two of them cannot share (a file, a port).
void readOutputs(YamlObject& root, Config& config) {
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
}

Config readConfig(const YAML::Node& document, const std::filesystem::path& file) {
  Diagnostics diag;
  Config config;
  config.file = file;
  YamlObject root(document, "", file, diag);
  readRig(root, config);
  for (const ConfigSection& section : configSections()) {
    if (section.prepare != nullptr) section.prepare(config);
    readSection(root, section.name, [&](YamlObject& s) { section.read(s, config); });
  }
  checkCorrectionScale(root, config);
  addWarnings(config);
  readOutputs(root, config);
  root.finish();
  diag.throwIfAny();
  return config;
}

}  // namespace

std::span<const ConfigSection> configSections() {
  static const std::array<ConfigSection, 12> kSections{{
      {"logging", [] { return loggingKeys().docs(); }, nullptr,
       [](YamlObject& s, Config& c) { loggingKeys().read(s, c); }},
      {"capture", [] { return captureKeys().docs(); }, nullptr,
       [](YamlObject& s, Config& c) { readCapture(s, c.capture); }},
      {"pipeline", [] { return pipelineKeys().docs(); }, nullptr,
       [](YamlObject& s, Config& c) { pipelineKeys().read(s, c.pipeline); }},
      {"processing", [] { return processingKeys().docs(); }, nullptr,
       [](YamlObject& s, Config& c) { processingKeys().read(s, c.processing); }},
      {"panorama", [] { return panoramaKeys().docs(); }, nullptr,
       [](YamlObject& s, Config& c) { readPanorama(s, c.panorama); }},
      {"colour_correction", [] { return colourKeys().docs(); }, nullptr,
       [](YamlObject& s, Config& c) {
         colourKeys().read(s, c.colour);
         checkBalanceReference(s, c);
       }},
      // Over the rig file's vehicle, before what follows it.
      {"vehicle", [] { return vehicleKeys().docs(); }, nullptr,
       [](YamlObject& s, Config& c) { c.vehicle = readVehicle(s); }},
      {"render", [] { return renderKeys().docs(); }, renderDefaults,
       [](YamlObject& s, Config& c) {
         readRender(s, c.render);
         checkNamesACamera(s, "split_camera", c.render.splitCamera, c);
       }},
      {"mesh", [] { return meshKeys().docs(); }, meshDefaults,
       [](YamlObject& s, Config& c) { readMesh(s, c.mesh); }},
      {"control", [] { return controlKeys().docs(); }, nullptr,
       [](YamlObject& s, Config& c) { readControl(s, c.control); }},
      {"vehicle_signals", [] { return vehicleSignalsKeys().docs(); }, nullptr,
       [](YamlObject& s, Config& c) { vehicleSignalsKeys().read(s, c.vehicleSignals); }},
      {"calibration_watch", [] { return calibrationWatchKeys().docs(); }, nullptr,
       [](YamlObject& s, Config& c) { calibrationWatchKeys().read(s, c.calibrationWatch); }},
  }};
  return kSections;
}

Config loadConfig(const std::filesystem::path& file) {
  return readConfig(parseYamlFile(file), file);
}

Config loadConfigText(const std::string& text, const std::filesystem::path& file) {
  return readConfig(parseYamlText(text, file), file);
}

}  // namespace surroundd::daemon
