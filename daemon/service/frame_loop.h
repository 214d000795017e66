#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <limits>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/calibration.h"
#include "core/contact.h"
#include "core/frame_pairer.h"
#include "core/touch_pipeline.h"
#include "io/frame_source.h"
#include "io/recording.h"
#include "io/touch_sink.h"
#include "service/arrival_rate.h"
#include "service/frame_pool.h"
#include "service/frame_queue.h"
#include "service/frame_tap.h"
#include "service/recording_thread.h"

namespace everytouch::service {

struct LoopStatistics {
    std::uint64_t frames = 0;   // camera frames taken from the source
    std::uint64_t pairs = 0;    // frame pairs formed
    std::uint64_t dropped = 0;  // frames the source lost, and frames dropped because the pipeline fell behind
    double frameRate = 0.0;     // camera frames per second over the last second
    double latencyMs = 0.0;  // from a frame's arrival to its contacts reaching the sinks, smoothed over ~1 s
    // How far the code on the table lies from where the calibration puts it, projector pixels
    // (core/registration_check.h); NaN until measured.
    double calibrationErrorPx = std::numeric_limits<double>::quiet_NaN();
    double mostCalibrationErrorPx = std::numeric_limits<double>::quiet_NaN();  // the largest so far
    double seconds = 0.0;  // wall-clock time since start, or of the whole run once finished
    // The detection pipeline's time per pair over the last kPipelineSamples pairs, ms (thread CPU time is not
    // measured: this is wall time on the pipeline thread, what the latency is made of).
    double pipelineMedianMs = 0.0;
    double pipelineP99Ms = 0.0;
    std::uint64_t pipelineFailures = 0;  // pairs on which a stage failed; their contacts were released
    // How often the code's sign swapped the order in which the camera's frames are taken (a camera that
    // started on the O - P frame, a refresh the projector missed; core/polarity_lock.h).
    std::uint64_t polaritySwaps = 0;
    // Why the recording stopped before the stream did (a full disk), with what it kept; empty otherwise.
    std::string recordingStopped;
    // Frames left out of the recording because writing fell behind the camera (service/recording_thread.h).
    std::uint64_t recordingDropped = 0;
};

struct LoopOptions {
    std::uint64_t maxFrames = 0;                                       // stop after N camera frames; 0: never
    std::size_t queueCapacity = 4;                                     // frames waiting between the threads
    FrameQueue::Overflow overflow = FrameQueue::Overflow::DropOldest;  // Block for sources that can wait
    // Frames waiting to be written to the recording: a live camera's burst of 67 ms at 120 Hz while the disk
    // is busy.
    std::size_t recordingCapacity = 8;
    // Threads that encode the recording's frames (service/recording_thread.h).
    int recordingEncoders = RecordingThread::defaultEncoders();
    // A live camera that delivers no frame for this long has stalled: every contact is released and detection
    // waits for frames. Nothing for sources that can wait (a replay or simulation run fast).
    std::optional<std::chrono::milliseconds> stallAfter;
};

// Runs on the pipeline thread when new settings take effect, before the next pair: the place for sinks that
// depend on the calibration (the virtual touchscreen's size).
using SettingsHook = std::function<void(const core::PipelineSettings&)>;

// Carries frames from a source through pairing and the detection pipeline to the sinks: a camera thread
// reads the source into a bounded queue, a pipeline thread pairs each new frame with the previous one, runs
// `pipeline` on the pair and publishes its contacts. The owner (the main thread) hears about news through
// `notify` and reads them here.
class FrameLoop {
public:
    // `notify` runs on the loop's threads whenever the contacts change or the loop ends; it must be cheap and
    // thread-safe. `pipeline` is used by the pipeline thread only, and must outlive the loop.
    FrameLoop(io::FrameSource& source, core::PairPipeline& pipeline, std::vector<io::TouchSink*> sinks,
              io::RecordingWriter* recorder, LoopOptions options, core::PipelineSettings settings,
              std::function<void()> notify, SettingsHook onSettings = nullptr);
    ~FrameLoop();
    FrameLoop(const FrameLoop&) = delete;
    FrameLoop& operator=(const FrameLoop&) = delete;

    void start();

    // Stops both threads without waiting for the rest of the stream; every contact is released first.
    void stop();

    // Whether the loop ended: the stream ended, `maxFrames` were taken, or it failed.
    bool finished() const { return finished_; }
    // Why the loop failed (camera, recording, sink); nothing after a normal end.
    std::optional<std::string> failure() const;
    // Why the source's camera cannot be reached while the loop waits for it to come back; nothing while
    // frames come. Said once every contact the frames before the loss showed is released.
    std::optional<std::string> sourceLost() const;

    LoopStatistics statistics() const;
    // The current contacts and a number that changes whenever they do.
    core::Contacts contacts(std::uint64_t& version) const;
    // The last time the pipeline thread showed it is alive (it wakes at least every 100 ms).
    std::chrono::steady_clock::time_point heartbeat() const;
    // Whether the pipeline is working on a pair now (a new calibration's preparation may take a while).
    bool processing() const { return processing_; }

    void setSettings(core::PipelineSettings settings);
    // The pipeline's latest correction of the calibration (core/calibration_correction.h) not taken yet.
    std::optional<core::CalibrationCorrection> takeCorrection();
    // Why the pipeline found the calibration off and did not correct it; empty otherwise.
    std::string calibrationProblem() const;
    // Whether detection ran on the last pair (calibrated, the code known, no failure, frames coming); why
    // not, when not.
    bool detecting() const { return detecting_; }
    // Whether detection does not run for a reason the loop has seen (a pair judged, or frames that stopped):
    // not before the first pair, nor before the first pair with new settings.
    bool idle() const { return judged_ && !detecting_; }
    // Whether a stage failed on the last pair.
    bool failing() const { return failingNow_; }
    std::string idleReason() const;
    FrameTap& tap() { return tap_; }

private:
    void runCamera();
    void runPipeline();
    void publish(std::uint64_t frameIndex, std::int64_t timestampUs, const core::Contacts& contacts);
    void processPair(const core::FramePair& pair, const core::PipelineSettings& settings);
    // The pipeline thread's side of a camera that stopped delivering: says so once and releases every
    // contact.
    void stalled(std::chrono::steady_clock::duration silence);
    void recordPipelineTime(double ms);
    // Hands a frame to the recording thread; a write that fails stops the recording, never the detection.
    void record(const core::Frame& frame);
    // On the recording thread.
    void stopRecording(const std::string& problem);
    void fail(const std::string& problem);
    // The camera thread's side of a lost camera: says so once, has the contacts released, and waits
    // `backOff` (doubled for the next time) before the source is asked again. False when stopping.
    bool waitForLostSource(const std::string& reason, std::chrono::milliseconds& backOff);
    void sourceBack();

    io::FrameSource& source_;
    core::PairPipeline& pipeline_;
    std::vector<io::TouchSink*> sinks_;
    io::RecordingWriter* recorder_;
    LoopOptions options_;
    std::function<void()> notify_;
    SettingsHook onSettings_;
    FrameQueue queue_;
    FramePool spareFrames_;  // images the pipeline thread is done with, for the camera thread to fill again
    std::optional<RecordingThread> recording_;  // with a recorder, from start() on
    FrameTap tap_;
    core::FramePairer pairer_;  // pipeline thread only

    std::atomic<bool> stopping_{false};
    std::atomic<bool> finished_{false};
    std::atomic<bool> detecting_{false};
    std::atomic<bool> judged_{false};
    std::atomic<bool> failingNow_{false};
    std::uint64_t polaritySwaps_ = 0;     // as the pipeline last reported them (pipeline thread)
    std::string calibrationProblemSeen_;  // as the pipeline last reported it (pipeline thread)
    std::atomic<std::int64_t> heartbeatNs_{0};
    std::atomic<bool> processing_{false};
    std::thread camera_;
    std::thread pipelineThread_;

    mutable std::mutex mutex_;  // guards everything below
    LoopStatistics statistics_;
    std::chrono::steady_clock::time_point started_;
    ArrivalRate arrivals_;
    core::Contacts contacts_;
    std::uint64_t contactsVersion_ = 0;
    std::optional<std::string> failure_;
    std::optional<std::string> sourceLost_;
    std::uint64_t losses_ = 0;               // the camera's, counted by the camera thread
    std::uint64_t lossesReleased_ = 0;       // those whose contacts the pipeline thread released
    std::condition_variable stopRequested_;  // wakes the camera thread waiting for a lost source
    core::PipelineSettings settings_;
    std::uint64_t settingsVersion_ = 0;
    std::string idleReason_;
    std::optional<core::CalibrationCorrection> correction_;
    std::string calibrationProblem_;
    // The last pipeline times (ms) in a ring, preallocated: recording one allocates nothing.
    std::vector<double> pipelineMs_;
    std::size_t pipelineSamples_ = 0;
};

}  // namespace everytouch::service
