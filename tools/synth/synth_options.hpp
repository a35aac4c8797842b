#pragma once
// Command line of surround-synth: what to render and where. Parsing validates every value and
// throws UsageError with one message naming the option (main prints it and exits 2).

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/calibration/calibration_targets.hpp"
#include "processing/rig.hpp"
#include "tools/synth/scene.hpp"

namespace surroundd::synth {

class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct SynthOptions {
  std::filesystem::path rig;     // rig preset YAML (sources not needed)
  std::filesystem::path out;     // output folder
  std::optional<cv::Size> size;  // per-camera image size; default: the preset's
  double seconds = 10;           // recording length
  double fps = 30;               // nominal frame rate
  std::uint64_t seed = 1;
  // random: per camera within the ranges of photometrics.hpp; identity: neutral, noise 0, no
  // drift; extreme: random, but gains and white balance at opposite ends of their ranges for
  // colour-correction sources and targets (the largest colour steps across seams).
  enum class Photometrics { kRandom, kIdentity, kExtreme };
  Photometrics photometrics = Photometrics::kRandom;
  bool drift = true;                                   // slow exposure drift
  double noiseSigma = 1.5;                             // sensor noise, 8-bit levels
  std::vector<std::pair<std::string, int>> dropEvery;  // camera name, N: omit every Nth frame
  // A camera that fails from a time on: its picture freezes, goes black, or it stops delivering.
  struct Fault {
    enum class Kind { kFreeze, kBlack, kStop };
    std::string camera;
    Kind kind = Kind::kStop;
    double fromS = 0;
  };
  std::vector<Fault> faults;
  // A camera knocked from a time on: its mount angles change by these degrees (a mirror folded,
  // a tailgate slammed); the recording's rig keeps the mount before.
  struct Turn {
    std::string camera;
    processing::MountAngles byDeg;
    double atS = 0;
  };
  std::vector<Turn> turns;
  std::optional<std::vector<int>> groundTruthFrames;  // default: first, middle, last
  SceneLayout scene = SceneLayout::kDefault;
  bool body =
      true;  // render the rig's `vehicle:` body (false: the same rig with nothing in the way)
  cv::Size panoramaSize{2048, 1024};
  int crf = 14;        // x264 CRF: visually lossless camera masters
  bool force = false;  // replace an existing output folder
  // Instead of a recording: one picture per camera of a calibration mat laid around the rig
  // (calibration_mat.hpp) with boards of this pattern, its layout and the true rig.
  std::optional<processing::Checkerboard> calibrationMat;
  std::vector<std::string> matAhead;  // cameras that also get a board straight ahead
  // Instead of a recording: this camera's view of a chessboard walked around its field, as an
  // image sequence with its true lens (calibration_session.hpp).
  std::optional<std::string> calibrationSession;

  int frameCount() const;
  // Everything that decides the recording's content (not --out or --force), in a fixed order:
  // part of the cache key and of the manifest.
  std::string canonical() const;
};

// `arguments` excludes the program name. Throws UsageError.
SynthOptions parseSynthArguments(std::span<const std::string_view> arguments);
bool wantsHelp(std::span<const std::string_view> arguments);
std::string synthUsage();

}  // namespace surroundd::synth
