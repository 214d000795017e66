#pragma once

#include <systemd/sd-bus.h>

#include "service/calibration_job.h"

namespace everytouch::service {

// The options dictionary (a{sv}) of the D-Bus Calibrate call, read from `message` where it stands: every key
// known and of its type, the values in range. Throws BusError (InvalidArgs) naming the option at fault.
CalibrationOptions readCalibrationOptions(sd_bus_message* message);

}  // namespace everytouch::service
