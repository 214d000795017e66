#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "io/camera_settings.h"

namespace everytouch::service {

// The range of TouchHeightMm: a finger whose pad is at most this high above the table touches it. Above 30 mm
// a hovering hand would click; below 0 nothing would.
inline constexpr double kMinTouchHeightMm = 0.0;
inline constexpr double kMaxTouchHeightMm = 30.0;

// The ranges of the camera keys: beyond them no camera of a touch table works (a pair of frames must come
// faster than a tap, an exposure must fit a frame, a gain beyond 60 dB is noise).
inline constexpr double kMinFrameRate = 1.0;
inline constexpr double kMaxFrameRate = 1000.0;
inline constexpr double kMinExposureUs = 1.0;
inline constexpr double kMaxExposureUs = 1'000'000.0;
inline constexpr double kMinGainDb = 0.0;
inline constexpr double kMaxGainDb = 60.0;
// A camera region smaller than this cannot hold a display's worth of code.
inline constexpr int kMinRegionSide = 64;

// Where the code comes from on a camera rig ([Projector] Output=): nowhere the daemon knows of, a projector
// that embeds it itself (a DLP development kit's pattern sequence, a media server) from the pattern of a
// seed, the daemon's own fullscreen window on the projector's output, which also shows the calibration
// images, or the daemon's translucent overlay over the desktop on that output (X11, through its compositing
// manager), which shows them too.
enum class ProjectorOutput { None, External, Window, Overlay };

// "none", "external", "window" or "overlay"; nothing for any other name.
std::optional<ProjectorOutput> parseProjectorOutput(std::string_view name);

struct ProjectorConfig {
    ProjectorOutput output = ProjectorOutput::None;  // [Projector] Output=
    std::uint64_t seed = 1;                          // [Projector] Seed=: the pattern's seed
    int delta = 10;       // [Projector] Delta=: its amplitude, projector levels (what a recording states)
    std::string display;  // [Projector] Display=: the window's output, by name or number; empty: the first

    bool operator==(const ProjectorConfig&) const = default;
};

// The daemon's configuration file, everytouchd.conf (documented key by key in everytouchd(8) and in the
// shipped example). Command-line options override it.
struct DaemonConfig {
    std::string rig;             // [Camera] Rig=: a --rig spec; empty when no camera is configured
    io::CameraSettings camera;   // [Camera] PixelFormat=, FrameRate=, ExposureUs=, GainDb=, Region=, Trigger=
    double touchHeightMm = 3.0;  // [Touch] HeightMm=: touching at or below this height, mm
    std::optional<bool> uinput;  // [Output] Uinput=: virtual touchscreen; unset: only for cameras
    std::filesystem::path calibrationPath;  // [Calibration] Path=: calibration store; empty: not configured
    bool correctCalibration = true;  // [Calibration] Correct=: correct it from the code while detection runs
    ProjectorConfig projector;       // [Projector]

    bool operator==(const DaemonConfig&) const = default;
};

// Reads `mainFile`, then every *.conf file in the directory `mainFile` + ".d" in lexical order; a later
// assignment replaces an earlier one and an empty value restores the default. A missing main file is fine
// unless `mustExist`. Throws io::InputError "FILE:LINE: [Section] Key: problem" for the first unknown key,
// bad value or malformed line.
DaemonConfig loadConfig(const std::filesystem::path& mainFile, bool mustExist);

// Every key the configuration file knows: section and key.
std::vector<std::pair<std::string, std::string>> configKeys();

// The drop-in directory of a main configuration file.
std::filesystem::path dropInDirectory(const std::filesystem::path& mainFile);

}  // namespace everytouch::service
