#pragma once
// The key tables (config_keys.hpp) of the config's sections, read by config_loader.cpp. Each
// output type's own keys are in its registration (output_type.hpp); the vehicle's in
// vehicle_yaml.hpp, shared with rig files. The rig's cameras (rig_yaml.hpp) have no table yet.

#include <span>
#include <string_view>
#include <vector>

#include "daemon/config/config.hpp"
#include "daemon/config/config_keys.hpp"
#include "daemon/config/yaml_reader.hpp"

namespace surroundd::daemon {

const ConfigKeys<Config>& loggingKeys();  // logging: the level, in Config itself
const ConfigKeys<CaptureConfig>& captureKeys();
const ConfigKeys<PipelineConfig>& pipelineKeys();
const ConfigKeys<ProcessingConfig>& processingKeys();
const ConfigKeys<PanoramaConfig>& panoramaKeys();
const ConfigKeys<ColourCorrectionConfig>& colourKeys();
const ConfigKeys<MeshConfig>& meshKeys();
const ConfigKeys<RenderConfig>& renderKeys();
const ConfigKeys<ControlConfig>& controlKeys();
const ConfigKeys<CalibrationWatchConfig>& calibrationWatchKeys();
// The keys every entry of `outputs:` has besides `type` (which picks the type's own keys).
const ConfigKeys<OutputConfig>& outputKeys();

// The bowl's rim when the config leaves it out: the wall rises over as much again as the floor's
// radius (far enough for a gentle slope), to a height in proportion.
double bowlRimRadiusM(const MeshConfig& mesh);
double bowlRimHeightM(const MeshConfig& mesh);

// A section of the config besides `rig` and `outputs` (the cameras; a list of outputs, each read
// by its type's keys): its name in the file, its keys' docs, and how it is read. The reader and
// the reference config's test walk the one list, configSections(), in the order it is read: a new
// section is one row there (config_loader.cpp).
struct ConfigSection {
  std::string_view name;
  std::vector<KeyDoc> (*docs)();
  // Before it is read, whether the file has it or not: defaults that follow the sections read
  // before it (the render's views follow the vehicle's size); null where it has none.
  void (*prepare)(Config& config);
  void (*read)(YamlObject& section, Config& config);  // what the file has of it
};
std::span<const ConfigSection> configSections();

}  // namespace surroundd::daemon
