#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <optional>
#include <thread>
#include <vector>

#include <opencv2/core/types.hpp>

#include "core/calibration.h"
#include "io/projector_output.h"
#include "service/calibration_job.h"
#include "service/frame_tap.h"

namespace everytouch::service {

// What one Calibrate call asked for.
struct CalibrationJob {
    std::vector<CalibrationStep> steps;
    CalibrationOptions options;
    std::optional<core::Calibration> start;  // the calibration active when the call came, if any
    cv::Size projectorSize;                  // the panel the steps' images are drawn for
};

// Runs the outcome of a job; see CalibrationRunner.
using FinishFunction = std::function<void(const CalibrationOutcome& outcome)>;

// One Calibrate job on its own thread, with its effects wired in: frame pairs come from the frame loop's tap,
// the steps' images go to the rig's projector output through an io::ProjectorLease, which gives the projector
// back however the job ends, and progress and the outcome go to the functions given. Destroying the runner
// cancels a job still running (a capture under way returns nothing) and waits for its thread.
class CalibrationRunner {
public:
    // `projector` is null for a recording, which shows what it shows. `queueFrames`: the frames the loop may
    // hold between the camera and the pipeline, which predate a newly shown image. `progress` and `finished`
    // run on the job's thread, `finished` once, last, also after a cancel or a failure. `tap` and
    // `projector` must outlive the runner.
    CalibrationRunner(FrameTap& tap, io::ProjectorOutput* projector, std::size_t queueFrames,
                      CalibrationJob job, ProgressFunction progress, FinishFunction finished);
    ~CalibrationRunner();
    CalibrationRunner(const CalibrationRunner&) = delete;
    CalibrationRunner& operator=(const CalibrationRunner&) = delete;

private:
    void run();
    std::optional<std::vector<core::FramePair>> capture(std::size_t pairs);

    FrameTap& tap_;
    io::ProjectorOutput* projector_;
    std::size_t queueFrames_;
    CalibrationJob job_;
    ProgressFunction progress_;
    FinishFunction finished_;
    std::atomic<bool> cancelled_{false};
    std::thread thread_;  // last: it starts once everything above is set
};

}  // namespace everytouch::service
