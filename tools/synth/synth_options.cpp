#include "tools/synth/synth_options.hpp"

#include <charconv>
#include <cmath>
#include <sstream>

#include <fmt/format.h>

namespace surroundd::synth {
namespace {

template <typename T>
T parseNumber(std::string_view option, std::string_view text, T min, T max, std::string_view what) {
  T value{};
  const auto* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (ec != std::errc() || ptr != end || !(value >= min && value <= max)) {
    throw UsageError(fmt::format("{}: expected {}, got '{}'", option, what, text));
  }
  return value;
}

cv::Size parseSize(std::string_view option, std::string_view text) {
  const auto x = text.find('x');
  const std::string what = "WIDTHxHEIGHT with even sides from 16 to 8192 (e.g. 1280x720)";
  if (x == std::string_view::npos) {
    throw UsageError(fmt::format("{}: expected {}, got '{}'", option, what, text));
  }
  try {
    const int w = parseNumber<int>(option, text.substr(0, x), 16, 8192, what);
    const int h = parseNumber<int>(option, text.substr(x + 1), 16, 8192, what);
    // H.264 in 4:4:4 is fine with odd sizes, but players and the 4:2:0 outputs downstream are not.
    if (w % 2 != 0 || h % 2 != 0) throw UsageError("");
    return {w, h};
  } catch (const UsageError&) {
    throw UsageError(fmt::format("{}: expected {}, got '{}'", option, what, text));
  }
}

std::vector<int> parseFrames(std::string_view option, std::string_view text) {
  std::vector<int> frames;
  std::size_t start = 0;
  while (start <= text.size()) {
    const auto comma = text.find(',', start);
    const auto item =
        text.substr(start, comma == std::string_view::npos ? text.npos : comma - start);
    frames.push_back(parseNumber<int>(option, item, 0, 10'000'000,
                                      "a comma-separated list of frame indices (e.g. 0,150,299)"));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return frames;
}

// COLSxROWS@SQUARE_M, e.g. 7x6@0.2.
processing::Checkerboard parseMatBoard(std::string_view option, std::string_view text) {
  const std::string what =
      "COLSxROWS@SQUARE_M: inner corners, each 2 to 64, and the square's side in metres from 0.01 "
      "to 2 (e.g. 7x6@0.2)";
  const auto x = text.find('x');
  const auto at = text.find('@');
  if (x == std::string_view::npos || at == std::string_view::npos || at < x) {
    throw UsageError(fmt::format("{}: expected {}, got '{}'", option, what, text));
  }
  try {
    return {{parseNumber<int>(option, text.substr(0, x), 2, 64, what),
             parseNumber<int>(option, text.substr(x + 1, at - x - 1), 2, 64, what)},
            parseNumber<double>(option, text.substr(at + 1), 0.01, 2.0, what)};
  } catch (const UsageError&) {
    throw UsageError(fmt::format("{}: expected {}, got '{}'", option, what, text));
  }
}

std::vector<std::string> parseNames(std::string_view text) {
  std::vector<std::string> names;
  std::size_t start = 0;
  while (start <= text.size()) {
    const auto comma = text.find(',', start);
    names.emplace_back(
        text.substr(start, comma == std::string_view::npos ? text.npos : comma - start));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return names;
}

}  // namespace

int SynthOptions::frameCount() const {
  return std::max(1, static_cast<int>(std::lround(seconds * fps)));
}

std::string SynthOptions::canonical() const {
  std::ostringstream s;
  s << "size=" << (size ? fmt::format("{}x{}", size->width, size->height) : "preset")
    << " seconds=" << fmt::format("{}", seconds) << " fps=" << fmt::format("{}", fps)
    << " seed=" << seed << " photometrics="
    << (photometrics == Photometrics::kRandom     ? "random"
        : photometrics == Photometrics::kIdentity ? "identity"
                                                  : "extreme")
    << " drift=" << drift << " noise_sigma=" << fmt::format("{}", noiseSigma) << " drop_every=";
  for (const auto& [name, n] : dropEvery) s << name << ":" << n << ";";
  s << " ground_truth_frames=";
  if (groundTruthFrames) {
    for (const int f : *groundTruthFrames) s << f << ";";
  } else {
    s << "default";
  }
  s << " panorama_size=" << panoramaSize.width << "x" << panoramaSize.height << " crf=" << crf;
  // Only when not the default, as for faults: earlier recordings keep their keys.
  if (scene != SceneLayout::kDefault) s << " scene=near-objects";
  if (!body) s << " body=off";
  if (!faults.empty()) {  // only then: earlier recordings keep their keys
    s << " faults=";
    for (const auto& f : faults) {
      s << f.camera << ":" << static_cast<int>(f.kind) << "@" << fmt::format("{}", f.fromS) << ";";
    }
  }
  if (!turns.empty()) {  // likewise
    s << " turns=";
    for (const auto& t : turns) {
      s << fmt::format("{}:{},{},{}@{};", t.camera, t.byDeg.yawDeg, t.byDeg.pitchDeg,
                       t.byDeg.rollDeg, t.atS);
    }
  }
  return s.str();
}

bool wantsHelp(std::span<const std::string_view> arguments) {
  for (const auto a : arguments) {
    if (a == "--help" || a == "-h") return true;
  }
  return false;
}

SynthOptions parseSynthArguments(std::span<const std::string_view> arguments) {
  SynthOptions o;
  bool haveRig = false, haveOut = false;
  for (std::size_t i = 0; i < arguments.size(); ++i) {
    const std::string_view option = arguments[i];
    const auto value = [&]() -> std::string_view {
      if (i + 1 >= arguments.size()) throw UsageError(fmt::format("{}: missing its value", option));
      return arguments[++i];
    };
    if (option == "--rig") {
      o.rig = std::string(value());
      haveRig = true;
    } else if (option == "--out") {
      o.out = std::string(value());
      haveOut = true;
    } else if (option == "--size") {
      o.size = parseSize(option, value());
    } else if (option == "--seconds") {
      o.seconds = parseNumber<double>(option, value(), 0.01, 3600.0, "seconds from 0.01 to 3600");
    } else if (option == "--fps") {
      o.fps = parseNumber<double>(option, value(), 1.0, 240.0, "frames per second from 1 to 240");
    } else if (option == "--seed") {
      o.seed = parseNumber<std::uint64_t>(option, value(), 0, UINT64_MAX, "a non-negative integer");
    } else if (option == "--photometrics") {
      const auto v = value();
      if (v != "random" && v != "identity" && v != "extreme") {
        throw UsageError(
            fmt::format("{}: expected 'random', 'identity' or 'extreme', got '{}'", option, v));
      }
      o.photometrics = v == "random"     ? SynthOptions::Photometrics::kRandom
                       : v == "identity" ? SynthOptions::Photometrics::kIdentity
                                         : SynthOptions::Photometrics::kExtreme;
    } else if (option == "--no-drift") {
      o.drift = false;
    } else if (option == "--noise-sigma") {
      o.noiseSigma = parseNumber<double>(option, value(), 0.0, 64.0, "8-bit levels from 0 to 64");
    } else if (option == "--drop-every") {
      const auto v = value();
      const auto colon = v.rfind(':');
      if (colon == std::string_view::npos || colon == 0) {
        throw UsageError(fmt::format("{}: expected CAMERA:N (e.g. right:3), got '{}'", option, v));
      }
      o.dropEvery.emplace_back(std::string(v.substr(0, colon)),
                               parseNumber<int>(option, v.substr(colon + 1), 2, 1'000'000,
                                                "CAMERA:N with N >= 2 (e.g. right:3)"));
    } else if (option == "--fault") {
      const auto v = value();
      const auto colon = v.find(':');
      const auto at = v.find('@');
      const auto kind =
          colon != std::string_view::npos && at != std::string_view::npos && colon < at
              ? v.substr(colon + 1, at - colon - 1)
              : std::string_view();
      if (colon == 0 || (kind != "freeze" && kind != "black" && kind != "stop")) {
        throw UsageError(fmt::format(
            "{}: expected CAMERA:freeze|black|stop@SECONDS (e.g. left:freeze@0.5), got '{}'",
            option, v));
      }
      o.faults.push_back({std::string(v.substr(0, colon)),
                          kind == "freeze"  ? SynthOptions::Fault::Kind::kFreeze
                          : kind == "black" ? SynthOptions::Fault::Kind::kBlack
                                            : SynthOptions::Fault::Kind::kStop,
                          parseNumber<double>(option, v.substr(at + 1), 0.0, 3600.0,
                                              "CAMERA:KIND@SECONDS with 0 <= SECONDS <= 3600")});
    } else if (option == "--turn") {
      const auto v = value();
      const auto colon = v.find(':');
      const auto at = v.find('@');
      const char* expected = "CAMERA:YAW,PITCH,ROLL@SECONDS in degrees (e.g. back:0,2,0@5)";
      if (colon == 0 || colon == std::string_view::npos || at == std::string_view::npos ||
          at < colon) {
        throw UsageError(fmt::format("{}: expected {}, got '{}'", option, expected, v));
      }
      const auto angles = v.substr(colon + 1, at - colon - 1);
      const auto comma1 = angles.find(',');
      const auto comma2 = comma1 == std::string_view::npos ? comma1 : angles.find(',', comma1 + 1);
      if (comma2 == std::string_view::npos) {
        throw UsageError(fmt::format("{}: expected {}, got '{}'", option, expected, v));
      }
      const auto angle = [&](std::string_view text) {
        return parseNumber<double>(option, text, -30.0, 30.0, expected);
      };
      o.turns.push_back(
          {std::string(v.substr(0, colon)),
           {angle(angles.substr(0, comma1)), angle(angles.substr(comma1 + 1, comma2 - comma1 - 1)),
            angle(angles.substr(comma2 + 1))},
           parseNumber<double>(option, v.substr(at + 1), 0.0, 3600.0, expected)});
    } else if (option == "--no-body") {
      o.body = false;
    } else if (option == "--scene") {
      const auto v = value();
      if (v != "default" && v != "near-objects") {
        throw UsageError(
            fmt::format("{}: expected 'default' or 'near-objects', got '{}'", option, v));
      }
      o.scene = v == "default" ? SceneLayout::kDefault : SceneLayout::kNearObjects;
    } else if (option == "--ground-truth-frames") {
      o.groundTruthFrames = parseFrames(option, value());
    } else if (option == "--panorama-size") {
      o.panoramaSize = parseSize(option, value());
    } else if (option == "--crf") {
      o.crf = parseNumber<int>(option, value(), 0, 51, "an x264 CRF from 0 (lossless) to 51");
    } else if (option == "--calibration-mat") {
      o.calibrationMat = parseMatBoard(option, value());
    } else if (option == "--calibration-session") {
      o.calibrationSession = std::string(value());
    } else if (option == "--mat-ahead") {
      o.matAhead = parseNames(value());
    } else if (option == "--force") {
      o.force = true;
    } else {
      throw UsageError(fmt::format("unknown option '{}' (see --help)", option));
    }
  }
  if (!haveRig) throw UsageError("--rig: missing (the rig preset YAML to render)");
  if (!haveOut) throw UsageError("--out: missing (the folder to write the recording to)");
  if (o.calibrationSession && o.calibrationMat) {
    throw UsageError("--calibration-session and --calibration-mat: give one");
  }
  if (o.photometrics == SynthOptions::Photometrics::kIdentity) {
    // Identity means neutral sensors: no noise, no drift, whatever else was asked.
    o.noiseSigma = 0;
    o.drift = false;
  }
  const int frames = o.frameCount();
  if (o.groundTruthFrames) {
    for (const int f : *o.groundTruthFrames) {
      if (f >= frames) {
        throw UsageError(fmt::format("--ground-truth-frames: frame {} is past the last frame {}", f,
                                     frames - 1));
      }
    }
  }
  return o;
}

std::string synthUsage() {
  return R"(surround-synth: renders a synthetic four-camera recording with ground truth.

usage: surround-synth --rig FILE --out DIR [options]

  --rig FILE                 rig preset YAML (cameras, lenses, mounts; sources not needed); its
                             `vehicle:` block, if any, is rendered as the car's body (with true
                             body masks in ground_truth/)
  --out DIR                  output folder: <camera>.mkv, rig.yaml, ground_truth.yaml,
                             ground_truth/*.png, manifest.yaml (written atomically)
  --size WxH                 image size of every camera (intrinsics scaled; default: preset's)
  --seconds S                length (default 10)
  --fps F                    frame rate (default 30)
  --seed N                   scene, photometrics, noise and timing (default 1)
  --photometrics MODE        random (default), identity (neutral, no noise, no drift) or
                             extreme (random, with gains 0.7 / 1.3 and white balance at the
                             ends of its range for colour sources / targets)
  --no-drift                 no slow exposure drift
  --noise-sigma X            sensor noise in 8-bit levels (default 1.5)
  --drop-every NAME:N        omit every Nth frame of camera NAME (repeatable)
  --fault NAME:KIND@S        from S seconds on, camera NAME freezes (repeats one picture), goes
                             black, or stops (its video ends); KIND freeze|black|stop (repeatable)
  --turn NAME:Y,P,R@S        from S seconds on, camera NAME is knocked: its mount's yaw, pitch
                             and roll change by Y, P, R degrees (up to 30; repeatable); the rig
                             written keeps the mount before, ground_truth.yaml has both
  --ground-truth-frames LIST frames with ground truth images (default: first, middle, last)
  --no-body                  leave the rig's vehicle body out (what the cameras would see
                             without it; the recording's rig then has no `vehicle:`)
  --scene LAYOUT             default, or near-objects: crates at the four seam directions and a
                             wall on the left, 1-3 m from the car at its start pose
  --panorama-size WxH        ground-truth panorama size (default 2048x1024)
  --crf N                    x264 CRF of the videos (default 14, visually lossless)
  --calibration-mat BOARD    instead of a recording: one picture per camera (NAME.png) of a
                             calibration mat laid around the rig, a board of pattern BOARD
                             (COLSxROWS@SQUARE_M, e.g. 7x6@0.2) in each overlap of two neighbouring
                             cameras, with its layout (mat.yaml, for surround-calibrate extrinsics
                             --mat) and the true rig (rig.yaml)
  --mat-ahead NAMES          with --calibration-mat: these cameras (comma-separated) also get a
                             board straight ahead
  --calibration-session NAME instead of a recording: camera NAME's view of a 9x6 chessboard
                             (5 cm squares) walked around its field and held still at 12 poses
                             that cover it, for --seconds at --fps: frame_0000.png ... (an image
                             sequence, frame_%04d.png) and rig.yaml with the camera's true lens
                             (for surround-calibrate guide)
  --force                    replace DIR if it exists (a DIR made by the same arguments, rig and
                             generator is kept as it is: "up to date")
  --help                     this text

exit status: 0 done or up to date, 1 failed while writing, 2 bad arguments or rig
)";
}

}  // namespace surroundd::synth
