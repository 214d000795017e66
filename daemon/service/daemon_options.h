#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "service/config.h"

#ifndef EVERYTOUCH_CONFIG_DIR
#define EVERYTOUCH_CONFIG_DIR "/etc/everytouch"
#endif

namespace everytouch::service {

inline constexpr const char* kDefaultConfigPath = EVERYTOUCH_CONFIG_DIR "/everytouchd.conf";
// The rig of a daemon started by hand with no camera configured: the simulator, to try everything out.
inline constexpr const char* kHandRunRig = "sim:demo";

// Everything the command line can set; the configuration file fills what it leaves open.
struct DaemonOptions {
    std::filesystem::path configPath = kDefaultConfigPath;  // --config
    std::string rig;  // --rig: sim[:scenario], replay:DIR, aravis[:ID], v4l2:/dev/videoN; empty: the config's
    std::filesystem::path touchLog;    // --log: JSON Lines touch log ("-" for stdout); empty for none
    std::vector<std::string> outputs;  // --output: "uinput" creates the virtual touchscreen
    std::filesystem::path recordDir;   // --record: write every frame (and ground truth) as a recording
    std::uint64_t maxFrames = 0;       // --frames: stop after this many camera frames; 0 runs until the end
    bool fast = false;                 // --fast: no real-time pacing for sim and replay rigs
    bool verbose = false;              // --verbose: debug logging, every contact change on stderr
    bool service = false;              // --service: run as the system service (no simulated fallback rig)
    std::string projector;  // --projector: none, external or window[:DISPLAY]; empty: the configuration's

    // The first problem found, naming the option; nothing when the options are usable.
    std::optional<std::string> validate() const;
};

// Sets [Projector] Output= (and Display= for a window or an overlay) from a --projector value: none,
// external, window, window:DISPLAY, overlay or overlay:DISPLAY. Throws io::InputError naming --projector for
// anything else.
void applyProjectorOption(const std::string& option, ProjectorConfig& projector);

}  // namespace everytouch::service
