#include "daemon/outputs/snapshot/snapshot_output.hpp"

#include <chrono>

#include <fmt/format.h>

#include "daemon/config/output_files.hpp"
#include "render/outputs/snapshot_sink.hpp"

namespace surroundd::daemon {
namespace {

void checkSnapshot(YamlObject& item, const OutputConfig& o,
                   const SnapshotOutputSettings& /*settings*/) {
  if (!o.path.empty() && o.path.extension() != ".png") {
    item.error("path", fmt::format("expected a file ending in .png, got '{}'", o.path.string()));
  }
}

// Not queued: it takes one picture a run, and which one depends on what it has written.
std::unique_ptr<render::FrameSink> openSnapshot(const OutputConfig& output,
                                                const OutputContext& /*context*/) {
  if (output.path.has_parent_path()) createOutputFolder(output.path.parent_path(), output.path);
  return std::make_unique<render::SnapshotSink>(
      output.path,
      std::chrono::duration_cast<std::chrono::nanoseconds>(
          std::chrono::duration<double>(settingsOf<SnapshotOutputSettings>(output).atSeconds)));
}

}  // namespace

OutputType snapshotOutputType() {
  OutputType type;
  type.name = "snapshot";
  type.pathDoc = "the picture: .png";
  readsSettings<SnapshotOutputSettings>(
      type,
      {ConfigKey<SnapshotOutputSettings>::number("at_s", &SnapshotOutputSettings::atSeconds,
                                                 {0.0, 1e7, false, "seconds of stream time"},
                                                 "stream time of the snapshot")},
      checkSnapshot);
  type.pathUse = [](const OutputConfig&) { return OutputPathUse::kReplaced; };
  type.openPictureSink = openSnapshot;
  return type;
}

}  // namespace surroundd::daemon
