#pragma once

#include <cstddef>
#include <string>

#include "eval/detected_contacts.h"
#include "eval/touch_trials.h"
#include "io/frame_source.h"
#include "io/rig_description.h"

namespace everytouch::eval {

// What the pipeline found on a live frame source and what the source knew was there, frame by frame.
struct SourceRun {
    io::RigDescription rig;
    TruthFrames truth;
    DetectedFrames detected;
};

// Runs core::TouchPipeline over a source that knows its ground truth (the simulated rig) as the daemon does,
// each frame paired with the previous one, keeping each frame's truth and contacts but not its image: a
// grid35 cell of 105 taps is 20 000 frames, some 19 GB as a recording. Stops when the source ends or after
// maxFrames frames (0: no limit). Throws io::InputError naming `name` when the source describes no rig
// (calibration and code) or has no ground truth.
SourceRun runOnSource(io::FrameSource& source, const std::string& name, std::size_t maxFrames,
                      const core::DetectionOptions& options, double touchHeightMm);

}  // namespace everytouch::eval
