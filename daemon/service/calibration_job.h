#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "core/calibration.h"
#include "core/frame.h"
#include "core/result.h"

namespace everytouch::service {

// The options a Calibrate call may carry (its a{sv}).
struct CalibrationOptions {
    unsigned pairsPerStep = 8;   // "frames" (u): frame pairs the table step averages, 1..120
    double cardWidthMm = 85.5;   // "card_width_mm" (d): the rectangle the steps look for; a credit
    double cardHeightMm = 12.5;  // "card_height_mm" (d): card's magnetic stripe by default
    unsigned views = 6;          // "views" (u): poses the projector step takes, the table first, 3..20
    double viewTimeoutS = 60.0;  // "view_timeout_s" (d): the projector step fails when no new pose is
                                 // taken for this long (camera time), 1..3600 s

    // The first problem found, naming the option; nothing when the options are usable.
    std::optional<std::string> validate() const;
};

// What a step makes of what it captured: a new calibration and its RMS reprojection error.
struct Estimate {
    core::Calibration calibration;
    double rmsPx = 0.0;
    cv::Mat scene;  // the texture (8-bit gray) the step measured last: the scene as the step left it
};
// The estimate, or the reason the step could not find one.
using EstimateResult = core::Result<Estimate>;

// Captures the next `pairs` frame pairs; nothing when none came (camera gone, job cancelled).
using CaptureFunction = std::function<std::optional<std::vector<core::FramePair>>(std::size_t pairs)>;
// Asks the projector to show an image (8-bit, projector size) from the next frames on; does nothing when
// the frames come from a recording, which shows what it shows.
using ShowFunction = std::function<void(const cv::Mat& projectorImage)>;
// Reports progress: the step, the fraction of the whole job done (0..1) and a sentence for the user.
using ProgressFunction =
    std::function<void(const std::string& step, double fraction, const std::string& message)>;

// What a step works with.
struct StepContext {
    const CalibrationOptions& options;
    // The calibration before this step (the previous step's result within one job), if any.
    const std::optional<core::Calibration>& current;
    cv::Size projectorSize;  // the panel the step's images are drawn for
    CaptureFunction capture;
    ShowFunction show;
    // Progress within the step: fraction 0..1 of the step, a sentence for the user.
    std::function<void(double fraction, const std::string& message)> progress;
    // The scene the step before this one in the same job measured last (Estimate::scene): the camera may
    // still see what that step needed. Empty when this step is the job's first.
    cv::Mat previousScene;
};

using StepRunner = std::function<EstimateResult(const StepContext& context)>;

struct CalibrationStep {
    std::string name;         // as Calibrate names it: "projector", "table"
    std::string description;  // what it measures, for messages
    StepRunner run;
};

// The steps a Calibrate `step` argument stands for ("full" is projector then table); nothing for an unknown
// name.
std::optional<std::vector<CalibrationStep>> calibrationSteps(std::string_view request);
inline constexpr const char* kCalibrationRequests = "projector, table or full";

struct CalibrationOutcome {
    bool ok = false;
    std::string message;
    double rmsPx = 0.0;  // the worst step's RMS reprojection error
    std::optional<core::Calibration> calibration;
};

// Runs the steps of one Calibrate call in order, each feeding its result to the next. Stops at the first
// failure; the outcome then carries no calibration, so the caller keeps the previous one.
CalibrationOutcome runCalibration(const std::vector<CalibrationStep>& steps,
                                  const CalibrationOptions& options,
                                  const std::optional<core::Calibration>& start, cv::Size projectorSize,
                                  const CaptureFunction& capture, const ShowFunction& show,
                                  const ProgressFunction& progress);

}  // namespace everytouch::service
