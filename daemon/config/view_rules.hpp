#pragma once
// vehicle_signals: in the config — how long a signal stays fresh, and the view rules: which view
// the vehicle's signals bring up (reverse gear: the top view; an indicator: the split view on that
// side, ...). The service evaluates them on every loop and switches the surround outputs when
// the rule that holds changes; with none holding, the view chosen last by hand comes back.

#include <optional>
#include <span>

#include "daemon/config/config.hpp"
#include "daemon/config/config_keys.hpp"
#include "daemon/config/yaml_reader.hpp"

namespace surroundd::daemon {

const ConfigKeys<VehicleSignalsConfig>& vehicleSignalsKeys();

// The first rule whose every condition holds for `signals`, if any.
const ViewRule* ruleThatHolds(std::span<const ViewRule> rules,
                              const vehicle::VehicleSignals& signals);
// "gear R, speed below 10 km/h", for the log and the status.
std::string describe(const ViewRule& rule);

}  // namespace surroundd::daemon
