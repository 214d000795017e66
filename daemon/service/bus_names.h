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

// Properties.
inline constexpr const char* kPropertyApiVersion = "APIVersion";
inline constexpr const char* kPropertyState = "State";
inline constexpr const char* kPropertyStateReason = "StateReason";
inline constexpr const char* kPropertyRig = "Rig";
inline constexpr const char* kPropertyProjector = "Projector";
inline constexpr const char* kPropertyCalibrated = "Calibrated";
inline constexpr const char* kPropertyDisplaySize = "DisplaySize";
inline constexpr const char* kPropertyDisplaySizeMm = "DisplaySizeMm";
inline constexpr const char* kPropertyFrameRate = "FrameRate";
inline constexpr const char* kPropertyLatencyMs = "LatencyMs";
inline constexpr const char* kPropertyDroppedFrames = "DroppedFrames";
inline constexpr const char* kPropertyCalibrationErrorPx = "CalibrationErrorPx";
inline constexpr const char* kPropertyTouchHeightMm = "TouchHeightMm";
inline constexpr const char* kPropertyDevicePath = "DevicePath";

// Methods.
inline constexpr const char* kMethodCalibrate = "Calibrate";
inline constexpr const char* kMethodSaveCalibration = "SaveCalibration";
inline constexpr const char* kMethodResetCalibration = "ResetCalibration";
inline constexpr const char* kMethodReloadConfig = "ReloadConfig";
inline constexpr const char* kMethodSnapshot = "Snapshot";
inline constexpr const char* kMethodShowAccuracyTargets = "ShowAccuracyTargets";

// Signals.
inline constexpr const char* kSignalContacts = "Contacts";
inline constexpr const char* kSignalCalibrationProgress = "CalibrationProgress";
inline constexpr const char* kSignalCalibrationFinished = "CalibrationFinished";
inline constexpr const char* kSignalCalibrationCorrected = "CalibrationCorrected";

// The keys of Calibrate's options dictionary.
inline constexpr const char* kOptionFrames = "frames";
inline constexpr const char* kOptionCardWidthMm = "card_width_mm";
inline constexpr const char* kOptionCardHeightMm = "card_height_mm";
inline constexpr const char* kOptionViews = "views";
inline constexpr const char* kOptionViewTimeoutS = "view_timeout_s";

// The group whose members may change the daemon's state besides root.
inline constexpr const char* kPrivilegedGroup = "everytouch";

}  // namespace everytouch::bus
