#include "service/calibration_job.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace everytouch::service {

namespace {

constexpr unsigned kMaxPairsPerStep = 120;  // one second of a 120 Hz camera
constexpr double kMaxCardSideMm = 1000.0;   // larger than any table the rig sees

CalibrationStep projectorStep() {
    return {"projector", "the projected chessboard seen by the camera (H_CP)",
            "Keep the table clear: the projector shows a chessboard", nullptr};
}

CalibrationStep tableStep() {
    return {"table", "a card of known size lying on the table (H_TC)",
            "Lay the card flat on the table inside the projected area", nullptr};
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
