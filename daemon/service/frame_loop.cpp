#include "service/frame_loop.h"

#include <chrono>

namespace everytouch::service {

FrameLoop::FrameLoop(io::FrameSource& source, std::vector<io::TouchSink*> sinks,
                     io::RecordingWriter* recorder, std::uint64_t maxFrames)
    : source_(source), sinks_(std::move(sinks)), recorder_(recorder), maxFrames_(maxFrames) {}

void FrameLoop::publish(std::uint64_t frameIndex, std::int64_t timestampUs, const core::Contacts& contacts) {
    for (io::TouchSink* sink : sinks_)
        sink->publish(frameIndex, timestampUs, contacts);
}

LoopStatistics FrameLoop::run(const std::atomic<bool>& stop) {
    LoopStatistics statistics;
    const auto start = std::chrono::steady_clock::now();
    std::uint64_t lastIndex = 0;
    std::int64_t lastTimestampUs = 0;
    const core::Contacts noContacts;
    while (!stop && (maxFrames_ == 0 || statistics.frames < maxFrames_)) {
        std::optional<core::Frame> frame = source_.next();
        if (!frame)
            break;
        ++statistics.frames;
        lastIndex = frame->index;
        lastTimestampUs = frame->timestampUs;
        if (recorder_) {
            recorder_->addFrame(*frame);
            if (const auto truth = source_.truth())
                recorder_->addTruth(*truth);
        }
        if (std::optional<core::FramePair> pair = pairer_.push(*frame)) {
            ++statistics.pairs;
            // Detection stages plug in here; until they exist no finger is ever reported.
            publish(frame->index, frame->timestampUs, noContacts);
        }
    }
    publish(lastIndex, lastTimestampUs, noContacts);
    if (recorder_)
        recorder_->flush();
    statistics.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return statistics;
}

}  // namespace everytouch::service
