#pragma once

#include <filesystem>
#include <vector>

#include "core/contact.h"
#include "core/frame_pairer.h"
#include "core/touch_pipeline.h"
#include "io/recording.h"
#include "io/touch_log.h"

namespace everytouch::eval {

// What a detector reported, frame by frame in the recording's frame order: the contacts in effect after
// each frame (a set holds until the detector reports another, as in the touch log).
using DetectedFrames = std::vector<core::Contacts>;

// A touch log made from `recording` (docs/file-formats.md) as the contacts of each frame. Throws
// io::InputError naming the log and the line whose index is not one of the recording's frames.
DetectedFrames contactsFromLog(const io::Recording& recording, const std::vector<io::TouchLogEntry>& log,
                               const std::filesystem::path& logPath);

// Runs core::TouchPipeline frame by frame as the daemon does (each frame paired with the previous one of
// opposite polarity, the contacts reported at the newer frame), with a rig's calibration and code.
class PipelineContacts {
public:
    PipelineContacts(const io::RigDescription& rig, const core::DetectionOptions& options,
                     double touchHeightMm);
    // Appends the contacts in effect after `frame` to `frames`: the pipeline's when the frame completes a
    // pair, the previous frame's otherwise.
    void add(const core::Frame& frame, DetectedFrames& frames);

private:
    core::TouchPipeline pipeline_;
    core::PipelineSettings settings_;
    core::FramePairer pairer_;
};

// PipelineContacts over `recording`'s frames.
DetectedFrames contactsFromPipeline(const io::Recording& recording, const core::DetectionOptions& options,
                                    double touchHeightMm);

}  // namespace everytouch::eval
