#include "service/calibration_job.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "service/table_set_up_step.h"

namespace everytouch::service {

namespace {

constexpr unsigned kMaxPairsPerStep = 120;  // one second of a 120 Hz camera
constexpr double kMaxCardSideMm = 1000.0;   // larger than any table the rig sees

// The one-time calibration of the rigid projector-camera pair needs a board in several tilted poses, each
// captured on the user's word; core::calibrateProjectorCameraPair exists, the capture dialogue does not yet.
CalibrationStep projectorStep() {
    return {"projector",
            "the one-time calibration of the projector-camera pair from several poses of a board",
            "Hold the board still in the next pose", nullptr};
}

CalibrationStep tableStep() {
    return {
        "table", "the table set-up from the projected chessboard and the card (H_CP, H_TC, keystone)",
        "The projector shows a chessboard: keep the table clear and lay the card flat in the white border "
        "below the board",
        setUpTableFromPairs};
}

}  // namespace

std::optional<std::string> CalibrationOptions::validate() const {
    if (pairsPerStep < 1 || pairsPerStep > kMaxPairsPerStep)
        return "frames: must be from 1 to " + std::to_string(kMaxPairsPerStep);
    for (const auto& [name, value] :
         {std::pair{"card_width_mm", cardWidthMm}, {"card_height_mm", cardHeightMm}})
        if (!std::isfinite(value) || value <= 0.0 || value > kMaxCardSideMm)
            return std::string(name) + ": must be more than 0 and at most " +
                   std::to_string(int(kMaxCardSideMm)) + " mm";
    return std::nullopt;
}

std::optional<std::vector<CalibrationStep>> calibrationSteps(std::string_view request) {
    if (request == "projector")
        return std::vector{projectorStep()};
    if (request == "table")
        return std::vector{tableStep()};
    if (request == "full")
        return std::vector{projectorStep(), tableStep()};
    return std::nullopt;
}

std::optional<std::string> missingEstimator(const std::vector<CalibrationStep>& steps) {
    for (const CalibrationStep& step : steps)
        if (!step.estimator)
            return "The " + step.name + " step (" + step.description + ") is not part of this build yet";
    return std::nullopt;
}

CalibrationOutcome runCalibration(const std::vector<CalibrationStep>& steps,
                                  const CalibrationOptions& options,
                                  const std::optional<core::Calibration>& start,
                                  const CaptureFunction& capture, const ProgressFunction& progress) {
    CalibrationOutcome outcome;
    std::optional<core::Calibration> current = start;
    const double stepShare = 1.0 / static_cast<double>(steps.size());
    for (std::size_t i = 0; i < steps.size(); ++i) {
        const CalibrationStep& step = steps[i];
        const double begun = stepShare * static_cast<double>(i);
        progress(step.name, begun, step.prompt);
        const std::optional<std::vector<core::FramePair>> pairs = capture(options.pairsPerStep);
        if (!pairs) {
            outcome.message = "the " + step.name + " step got no camera frames";
            return outcome;
        }
        progress(step.name, begun + 0.5 * stepShare, "Estimating " + step.description);
        EstimateResult result = step.estimator(*pairs, current, options);
        if (!result.calibration) {
            outcome.message = "the " + step.name + " step failed: " + result.problem;
            return outcome;
        }
        current = std::move(result.calibration);
        outcome.rmsPx = std::max(outcome.rmsPx, result.rmsPx);
        progress(step.name, begun + stepShare, "Done with " + step.description);
    }
    outcome.ok = true;
    outcome.calibration = std::move(current);
    char rms[32];
    std::snprintf(rms, sizeof rms, "%.2f", outcome.rmsPx);
    outcome.message = "calibrated; RMS reprojection error " + std::string(rms) + " px";
    return outcome;
}

}  // namespace everytouch::service
