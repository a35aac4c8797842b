#pragma once
// vehicle_signals.can in the config: the CAN interface, the DBC file, and for each of gear,
// steering_deg, speed_kmh and indicator the CAN signal that carries it — named in the DBC file
// ({signal: NAME}) or written out ({id, extended, start_bit, length, byte_order, signed, factor,
// offset}) — with, for gear and indicator, which of its numbers means what ({values: {R: 2, ...}}).
// The DBC file is read whole at config load, so --check-config names a signal it lacks.

#include "daemon/config/config.hpp"
#include "daemon/config/yaml_reader.hpp"

namespace surroundd::daemon {

// Reads section's `can` key, if there, into c.can; problems go to the section's diagnostics.
void readCanMapping(YamlObject& section, VehicleSignalsConfig& c);

}  // namespace surroundd::daemon
