#pragma once
// surround-calibrate import: a calibration made by another tool (OpenCV FileStorage files,
// OCamCalib's calib_results.txt, the pjlab layouts) in, a rig file in the vehicle frame out.

#include <ostream>
#include <string>
#include <vector>

#include "daemon/config/rig_yaml.hpp"
#include "tools/calibrate/import/import_options.hpp"

namespace surroundd::calibrate {

struct ImportedRig {
  // In the order front, right, back, left, then the others. Picture paths are relative to the
  // folder of options.out.
  std::vector<daemon::RigCamera> cameras;
  std::string header;  // the rig file's comment: the inputs, the frame options, the command
  // What the user should know of how each camera was read: a pose fitted to a homography (with
  // how far from it), a warning where the fit is poor or a camera's name and pose disagree.
  std::vector<std::string> notes;
  // Per camera, in the order read: what each part of its calibration was taken from.
  std::vector<std::string> sources;
};

// The rig the options describe. Throws UsageError naming the file and key for missing or
// malformed input.
ImportedRig importRig(const ImportOptions& options);

// importRig, then writes options.out (beside and renamed) and prints the notes and each camera's
// mount to `log`.
void runImport(const ImportOptions& options, std::ostream& log);

}  // namespace surroundd::calibrate
