#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

#include "core/frame_pairer.h"
#include "io/frame_source.h"
#include "io/recording.h"
#include "io/touch_sink.h"

namespace everytouch::service {

struct LoopStatistics {
    std::uint64_t frames = 0;  // camera frames taken from the source
    std::uint64_t pairs = 0;   // frame pairs formed
    double seconds = 0.0;      // wall-clock time of the run
};

// Carries frames from a source through pairing and the pipeline stages to the sinks, in one thread.
class FrameLoop {
public:
    FrameLoop(io::FrameSource& source, std::vector<io::TouchSink*> sinks, io::RecordingWriter* recorder,
              std::uint64_t maxFrames);

    // Runs until the source ends, `maxFrames` frames were taken or `stop` becomes true; then releases every
    // contact.
    LoopStatistics run(const std::atomic<bool>& stop);

private:
    void publish(std::uint64_t frameIndex, std::int64_t timestampUs, const core::Contacts& contacts);

    io::FrameSource& source_;
    std::vector<io::TouchSink*> sinks_;
    io::RecordingWriter* recorder_;
    std::uint64_t maxFrames_;
    core::FramePairer pairer_;
};

}  // namespace everytouch::service
