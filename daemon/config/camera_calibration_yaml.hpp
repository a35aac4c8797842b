#pragma once
// A rig camera's `lens:` and `mount:` in YAML (the keys: rig_yaml.hpp), checked for what no real
// lens or mount has. Errors go to the object's Diagnostics.

#include <string_view>

#include "daemon/config/yaml_reader.hpp"
#include "processing/rig.hpp"

namespace surroundd::daemon {

// The lens of camera `camera` (named in messages): pinhole, fisheye or OCamCalib's model.
processing::Intrinsics readLens(YamlObject& lens, std::string_view camera);
// Its position and orientation in the vehicle frame: yaw/pitch/roll or a unit quaternion.
processing::Pose readMount(YamlObject& mount);

}  // namespace surroundd::daemon
