#pragma once
// Writes a whole synthetic recording: plans it, renders every frame of every camera, encodes the
// videos on worker threads, writes ground truth and the rig, and publishes the folder atomically
// (built as "<out>.tmp-<pid>", renamed to <out> when complete).

#include <filesystem>
#include <ostream>

#include "tools/synth/synth_options.hpp"

namespace surroundd::synth {

struct RecordingResult {
  bool upToDate = false;  // the folder already held this recording; nothing was done
  std::filesystem::path folder;
  int frames = 0;
  double seconds = 0;  // wall time of the whole run
};

// Throws UsageError for bad input (rig, camera names, an existing folder without --force) and
// std::exception for failures while writing; the output folder is then left as it was.
RecordingResult writeRecording(const SynthOptions& options, std::ostream& log);

}  // namespace surroundd::synth
