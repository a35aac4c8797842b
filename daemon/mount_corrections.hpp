#pragma once
// What the service may ask of the mount corrections the calibration watch made
// (calibration_watch.correct: apply; daemon/stages/calibration_watch_stage.hpp), so that the
// pipeline names no stage: the mounts corrected since the run started or they were last accepted,
// keeping them (once the service has written them into the rig file), and going back on them.
// Threads: the pipeline thread only.

#include <string>
#include <utility>
#include <vector>

#include "processing/rig.hpp"

namespace surroundd::daemon {

class MountCorrections {
 public:
  virtual ~MountCorrections() = default;
  MountCorrections() = default;
  MountCorrections(const MountCorrections&) = delete;
  MountCorrections& operator=(const MountCorrections&) = delete;

  // Each camera whose mount in the panorama now differs from the kept one (the run's start, or
  // the last accepted()): its name and its mount now.
  virtual std::vector<std::pair<std::string, processing::Pose>> correctedMounts() const = 0;
  // The mounts in the panorama now are the ones kept from here on.
  virtual void accepted() = 0;
  // Back to the kept mounts, from the set after their table is made, and no more corrections
  // made this run (they are only suggested); what it did, for the reply.
  virtual std::string revert() = 0;
};

}  // namespace surroundd::daemon
