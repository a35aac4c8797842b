#pragma once
// The `snapshot` output type: one PNG of the frame at `at_s`, or of the last one.

#include "daemon/config/output_type.hpp"

namespace surroundd::daemon {

struct SnapshotOutputSettings {
  double atSeconds = 1.0;  // stream time of the snapshot; the last frame if the run is shorter

  bool operator==(const SnapshotOutputSettings&) const = default;
};

OutputType snapshotOutputType();

}  // namespace surroundd::daemon
