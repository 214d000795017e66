#include "eval/detected_contacts.h"

#include <string>
#include <unordered_map>

#include "io/input_error.h"

namespace everytouch::eval {

DetectedFrames contactsFromLog(const io::Recording& recording, const std::vector<io::TouchLogEntry>& log,
                               const std::filesystem::path& logPath) {
    std::unordered_map<std::uint64_t, std::size_t> positionOf;
    for (std::size_t position = 0; position < recording.frames().size(); ++position)
        positionOf.emplace(recording.frames()[position].index, position);
    DetectedFrames frames(recording.frames().size());
    std::size_t filled = 0;  // frames before this hold the contacts of the entries read so far
    const core::Contacts* current = nullptr;
    for (const io::TouchLogEntry& entry : log) {
        const auto found = positionOf.find(entry.index);
        if (found == positionOf.end())
            throw io::InputError(logPath.string(), "line " + std::to_string(entry.line),
                                 "index " + std::to_string(entry.index) +
                                     " is not a frame of the recording; was the log made from it?");
        for (; filled < found->second; ++filled)
            if (current)
                frames[filled] = *current;
        current = &entry.contacts;
    }
    for (; filled < frames.size(); ++filled)
        if (current)
            frames[filled] = *current;
    return frames;
}

PipelineContacts::PipelineContacts(const io::RigDescription& rig, const core::DetectionOptions& options,
                                   double touchHeightMm)
    : pipeline_(options), settings_{rig.calibration, rig.pattern, touchHeightMm} {}

void PipelineContacts::add(const core::Frame& frame, DetectedFrames& frames) {
    frames.push_back(frames.empty() ? core::Contacts{} : frames.back());
    if (const std::optional<core::FramePair> pair = pairer_.push(frame))
        frames.back() = pipeline_.process(*pair, settings_).contacts;
}

DetectedFrames contactsFromPipeline(const io::Recording& recording, const core::DetectionOptions& options,
                                    double touchHeightMm) {
    PipelineContacts pipeline(recording.rig(), options, touchHeightMm);
    DetectedFrames frames;
    frames.reserve(recording.frames().size());
    for (std::size_t position = 0; position < recording.frames().size(); ++position)
        pipeline.add(recording.loadFrame(position), frames);
    return frames;
}

}  // namespace everytouch::eval
