#pragma once

#include <memory>

#include "io/camera_settings.h"
#include "io/frame_source.h"
#include "io/projector_output.h"
#include "io/rig_spec.h"

namespace everytouch::service {

// What a --rig spec gives the daemon: its frames and, when it has one, the output that shows calibration
// images on its projector.
struct OpenedRig {
    std::unique_ptr<io::FrameSource> source;
    std::unique_ptr<io::ProjectorOutput> projector;  // none for a recording, which shows what it shows
};

// Opens the rig a --rig spec names; a camera gets `camera`. Throws InputError when the spec cannot be served.
OpenedRig openRig(const io::RigSpec& spec, bool fast, const io::CameraSettings& camera);

}  // namespace everytouch::service
