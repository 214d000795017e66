#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/calibration.h"
#include "core/frame.h"

namespace everytouch::service {

// The options a Calibrate call may carry (its a{sv}).
struct CalibrationOptions {
    unsigned pairsPerStep = 8;   // "frames" (u): frame pairs captured for each step, 1..120
    double cardWidthMm = 85.5;   // "card_width_mm" (d): the rectangle the table step looks for; a credit
    double cardHeightMm = 12.5;  // "card_height_mm" (d): card's magnetic stripe by default

    // The first problem found, naming the option; nothing when the options are usable.
    std::optional<std::string> validate() const;
};

// What an estimator makes of the captured pairs: a new calibration and its RMS reprojection error, or the
// reason it could not find one.
struct EstimateResult {
    std::optional<core::Calibration> calibration;
    double rmsPx = 0.0;
    std::string problem;
};

// current: the calibration before this step (the previous step's result within one job), if any.
using Estimator = std::function<EstimateResult(const std::vector<core::FramePair>& pairs,
                                               const std::optional<core::Calibration>& current,
                                               const CalibrationOptions& options)>;

struct CalibrationStep {
    std::string name;         // as Calibrate names it: "projector", "table"
    std::string description;  // what it measures, for messages
    std::string prompt;       // what the user sees or does while frames are captured
    Estimator estimator;      // empty while this build has no estimator for the step
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

// Captures the next `pairs` frame pairs; nothing when none came (camera gone, job cancelled).
using CaptureFunction = std::function<std::optional<std::vector<core::FramePair>>(std::size_t pairs)>;
// Reports progress: the step, the fraction of the whole job done (0..1) and a sentence for the user.
using ProgressFunction =
    std::function<void(const std::string& step, double fraction, const std::string& message)>;

// Which step cannot run because this build has no estimator for it, in words; nothing when all can.
std::optional<std::string> missingEstimator(const std::vector<CalibrationStep>& steps);

// Runs the steps of one Calibrate call in order (each must have an estimator, see missingEstimator): for
// each, capture the pairs, run the estimator on them, feed its result to the next step. Stops at the first
// failure; the outcome then carries no calibration, so the caller keeps the previous one.
CalibrationOutcome runCalibration(const std::vector<CalibrationStep>& steps,
                                  const CalibrationOptions& options,
                                  const std::optional<core::Calibration>& start,
                                  const CaptureFunction& capture, const ProgressFunction& progress);

}  // namespace everytouch::service
