#pragma once

#include <cstdint>

// Every D-Bus name of everytouchd, derived from one versioned root; shared by the daemon and its clients.
#define EVERYTOUCH_BUS_ROOT "org.everytouch.Daemon1"

namespace everytouch::bus {

inline constexpr const char* kBusName = EVERYTOUCH_BUS_ROOT;
inline constexpr const char* kObjectPath = "/org/everytouch/Daemon1";
inline constexpr const char* kInterface = EVERYTOUCH_BUS_ROOT;

// Raised when a client must rely on a changed meaning of the interface.
inline constexpr std::uint32_t kApiVersion = 1;

inline constexpr const char* kErrorNotCalibrated = EVERYTOUCH_BUS_ROOT ".Error.NotCalibrated";
inline constexpr const char* kErrorCalibrationFailed = EVERYTOUCH_BUS_ROOT ".Error.CalibrationFailed";
inline constexpr const char* kErrorBusy = EVERYTOUCH_BUS_ROOT ".Error.Busy";
inline constexpr const char* kErrorNoCamera = EVERYTOUCH_BUS_ROOT ".Error.NoCamera";
inline constexpr const char* kErrorInvalidConfig = EVERYTOUCH_BUS_ROOT ".Error.InvalidConfig";

// The group whose members may change the daemon's state besides root.
inline constexpr const char* kPrivilegedGroup = "everytouch";

}  // namespace everytouch::bus
