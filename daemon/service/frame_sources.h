#pragma once

#include <filesystem>
#include <memory>

#include "io/camera_settings.h"
#include "io/frame_source.h"
#include "io/projector_output.h"
#include "io/rig_spec.h"
#include "service/config.h"

namespace everytouch::service {

// What a --rig spec gives the daemon: its frames and, when it has one, the output that shows calibration
// images on its projector.
struct OpenedRig {
    std::unique_ptr<io::FrameSource> source;
    std::unique_ptr<io::ProjectorOutput> projector;  // none for a recording, which shows what it shows
    cv::Mat pattern;  // the code the projector output embeds, when the daemon draws it (a camera's window)
};

// Opens the rig a --rig spec names; a camera gets `camera`, and the projector window when `projector` asks
// for it (the simulated rig has its own projector), its code pattern kept in `stateDirectory` between starts.
// Throws InputError when the spec cannot be served.
OpenedRig openRig(const io::RigSpec& spec, bool fast, const io::CameraSettings& camera,
                  const ProjectorConfig& projector, const std::filesystem::path& stateDirectory);

}  // namespace everytouch::service
