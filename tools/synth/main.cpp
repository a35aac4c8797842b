// surround-synth: renders a synthetic four-camera rig recording with ground truth (see --help).

#include <iostream>
#include <string_view>
#include <vector>

extern "C" {
#include <libavutil/log.h>
}

#include "common/build_info.hpp"
#include "tools/synth/calibration_session.hpp"
#include "tools/synth/mat_scene_writer.hpp"
#include "tools/synth/recording_writer.hpp"
#include "tools/synth/synth_options.hpp"

int main(int argc, char** argv) {
  using namespace surroundd::synth;
  const std::vector<std::string_view> arguments(argv + 1, argv + argc);
  if (wantsHelp(arguments)) {
    std::cout << synthUsage();
    return 0;
  }
  if (!arguments.empty() && arguments.front() == "--version") {
    std::cout << surroundd::versionText("surround-synth");
    return 0;
  }
  av_log_set_level(AV_LOG_ERROR);  // x264's per-stream statistics would bury our one-line summary
  try {
    const SynthOptions options = parseSynthArguments(arguments);
    if (options.calibrationSession) {
      writeCalibrationSession(options, std::cout);
    } else if (options.calibrationMat) {
      writeMatScene(options, std::cout);
    } else {
      writeRecording(options, std::cout);
    }
    return 0;
  } catch (const UsageError& error) {
    std::cerr << "surround-synth: " << error.what() << "\n";
    return 2;
  } catch (const std::exception& error) {
    std::cerr << "surround-synth: failed: " << error.what() << "\n";
    return 1;
  }
}
