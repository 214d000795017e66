#pragma once

#include <memory>

#include "io/frame_source.h"
#include "io/rig_spec.h"

namespace everytouch::service {

// Opens the frame source a --rig spec names. Throws InputError when the spec cannot be served.
std::unique_ptr<io::FrameSource> openFrameSource(const io::RigSpec& spec, bool fast);

}  // namespace everytouch::service
