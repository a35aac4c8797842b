#pragma once
// Output types: each kind of output (`type:` in the config) registers, in one place, its schema
// (the keys it reads, with their defaults, units and ranges, as a table), its factory, and what it
// takes from the pipeline. The config loader, the checks on output files and the pipeline know
// outputs only through this registry, so adding an output is its own source file plus one line in
// builtInOutputTypes() (daemon/outputs/output_types.cpp) — or one registerOutputType() call, as
// tests do. The registry starts empty: this library does not link the kinds (nor their sinks'
// libraries); a program that reads configs registers them first
// (daemon/outputs/built_in_outputs.hpp: registerBuiltInOutputTypes()).
//
// A type left out of this build (a CMake option off, its library not found) is registered too,
// with how to build it in: a config that names it is refused with that message.
//
// Threads: register types before any config is loaded or pipeline built; lookups are read-only.

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

#include "daemon/config/camera_frames_sink.hpp"
#include "daemon/config/config.hpp"
#include "daemon/config/config_keys.hpp"
#include "daemon/config/yaml_reader.hpp"
#include "render/egl_context.hpp"
#include "render/outputs/frame_sink.hpp"

namespace surroundd::daemon {

// What an output takes from the pipeline.
enum class OutputInput {
  kPicture,       // each wanted frame set's picture of its stream, 8-bit BGR (render::FrameSink)
  kCameraFrames,  // every frame set's camera frames as captured (CameraFramesSink: a recording)
  // (A picture output may show the surround view on the GPU instead: FrameSink::presentsViews.)
};

// What the files an output writes at `path` are, for the rule that no run destroys another's data
// and no two outputs write one file (output_files.hpp).
enum class OutputPathUse {
  kNone,      // writes no file (a stream, a window)
  kReplaced,  // one file, replaced by each run (a snapshot: the newest picture)
  kKept,      // one file never overwritten: a run finds it taken and writes <stem>-N<ext>
  kSegments,  // <stem>-00001<ext>, ... beside `path`, numbered on after those already there
  kFolder,    // a folder of files, never overwritten (-N like kKept)
};

// What an output is opened with besides its config.
struct OutputContext {
  cv::Size pictureSize;     // of its stream's pictures (kPicture)
  double nominalFps = 30;   // the cameras' frame rate
  bool latestWins = false;  // live: a queue drops its oldest picture instead of waiting
  const std::vector<RigCamera>* cameras = nullptr;  // the rig (kCameraFrames)
  // The surround views' renderer, its context current on the thread that opens the output; null
  // where the config has no surround output. For a sink that shows the views on the GPU
  // (FrameSink::presentsViews()).
  render::EglContext* renderer = nullptr;
};

// Two outputs of one config that cannot both work: the key of the later one to blame, and why
// ("listens on port 8080 already").
struct OutputConflict {
  std::string key;
  std::string message;
};

struct OutputType {
  std::string name;  // the config's `type:`
  OutputInput input = OutputInput::kPicture;
  // Empty when this build has the type; else how to build it in, e.g. "configure with
  // -DSURROUNDD_WITH_HTTP=ON (needs libmicrohttpd-dev libturbojpeg0-dev)" (howToBuildIn()).
  std::string leftOut;
  // The file or folder it writes at `path`, a required key (the reference's doc of it); empty:
  // it takes no path.
  std::string pathDoc;
  // Its own keys, for the reference config (set with readSettings by readsSettings()).
  std::vector<KeyDoc> keyDocs;
  // Reads its own keys of one `outputs:` entry (`type`, `stream`, `view` and `path` are read
  // already, into `output`) into its settings; each problem is reported on `item`.
  std::function<OutputSettings(YamlObject& item, const OutputConfig& output)> readSettings;
  // What its `path` is (kNone when it has none).
  std::function<OutputPathUse(const OutputConfig& output)> pathUse = [](const OutputConfig&) {
    return OutputPathUse::kNone;
  };
  // Whether `output` cannot work beside `earlier`, an output of the same type (optional).
  std::function<std::optional<OutputConflict>(const OutputConfig& earlier,
                                              const OutputConfig& output)>
      conflict;
  // The factory for its input: opens the output, or throws (EncoderError, RenderError,
  // std::runtime_error) naming what could not be opened. A picture output that may block runs
  // behind a QueuedSink (see queuedSink()).
  std::function<std::unique_ptr<render::FrameSink>(const OutputConfig&, const OutputContext&)>
      openPictureSink;
  std::function<std::unique_ptr<CameraFramesSink>(const OutputConfig&, const OutputContext&)>
      openCameraFramesSink;
  // For a type whose outputs may show the surround views on the GPU (a window through EGL): the
  // renderer's context opened where it can draw into `output` (its X server), or null where this
  // output does not ask for that. Throws RenderError naming what could not be opened.
  std::function<std::unique_ptr<render::EglContext>(const OutputConfig& output)> openRenderer;
};

// Gives `type` its settings: `keys`, a table over `Settings` (config_keys.hpp) whose defaults are
// its fields' initialisers, then `check` (optional): what the table cannot say, across keys.
template <class Settings>
void readsSettings(
    OutputType& type, ConfigKeys<Settings> keys,
    std::function<void(YamlObject& item, const OutputConfig& output, const Settings& settings)>
        check = {}) {
  type.keyDocs = keys.docs();
  type.readSettings = [keys = std::move(keys), check = std::move(check)](
                          YamlObject& item, const OutputConfig& output) {
    Settings settings;
    keys.read(item, settings);
    if (check) check(item, output, settings);
    return OutputSettings(std::move(settings));
  };
}

// Every key a type's outputs have of their own, in the order the reference writes them: `path`
// where it takes one, then its settings'.
std::vector<KeyDoc> ownKeyDocs(const OutputType& type);
// Reads `path` into `output` where its type takes one.
void readOutputPath(YamlObject& item, const OutputType& type, OutputConfig& output);

// Adds a type; throws std::logic_error if its name is taken or it has no factory for its input
// (a left-out type needs none).
void registerOutputType(OutputType type);
// The type named `name`, or null.
const OutputType* findOutputType(std::string_view name);
// The type of an output of a loaded config; throws std::logic_error if it is not registered.
const OutputType& outputTypeOf(const OutputConfig& output);
// Every registered name, in registration order (for messages).
std::vector<std::string_view> outputTypeNames();

// `sink` on a thread of its own behind a bounded queue of `depth` pictures of `context`'s size:
// with context.latestWins the oldest waiting picture gives way, else the pipeline waits.
std::unique_ptr<render::FrameSink> queuedSink(std::unique_ptr<render::FrameSink> sink,
                                              const OutputContext& context, std::size_t depth);

}  // namespace surroundd::daemon
