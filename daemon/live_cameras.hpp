#pragma once
// The machine's live cameras as the config meets them: what is there (`surroundd --list-cameras`),
// which V4L2 node a camera with `device: auto` takes, and whether each V4L2 camera of the config
// can give the format and size it asks for (`surroundd --check-config`), asked before anything
// streams.

#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include "daemon/config/rig_yaml.hpp"

namespace surroundd::daemon {

// V4L2 capture nodes with their persistent names, formats, sizes and rates; libcamera's cameras
// where this build has libcamera.
void listCameras(std::ostream& out, const std::filesystem::path& dev = "/dev");

// The cameras, each V4L2 one whose device is `auto` given the next capture node (in number order)
// that no camera names, in the config's order; `said` gets a line per camera given one. Throws
// std::runtime_error naming the first camera left without one, and the nodes there are.
std::vector<RigCamera> withAutoDevices(std::vector<RigCamera> cameras,
                                       std::vector<std::string>& said,
                                       const std::filesystem::path& dev = "/dev");

// One message per V4L2 camera that cannot give what it asks: the node does not open, is not a
// capture device, or does not offer the format at the size (naming what it offers).
std::vector<std::string> cameraDeviceProblems(const std::vector<RigCamera>& cameras);

}  // namespace surroundd::daemon
