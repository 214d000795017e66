#include "service/calibration_job.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "service/projector_step.h"
#include "service/table_set_up_step.h"

namespace everytouch::service {

namespace {

constexpr unsigned kMaxPairsPerStep = 120;  // one second of a 120 Hz camera
constexpr double kMaxCardSideMm = 1000.0;   // larger than any table the rig sees
constexpr unsigned kMinViews = 3;           // the pair calibration needs the card on three surfaces
constexpr unsigned kMaxViews = 20;          // beyond this the views add time, not accuracy
constexpr double kMaxViewTimeoutS = 3600.0;

CalibrationStep projectorStep() {
    return {"projector",
            "the one-time calibration of the projector-camera pair from the table and a board in several "
            "tilts",
            calibrateProjectorCameraPairStep};
}

CalibrationStep tableStep() {
    return {"table", "the table set-up from the projected chessboard and the card (H_CP, H_TC, keystone)",
            setUpTableStep};
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
    if (views < kMinViews || views > kMaxViews)
        return "views: must be from " + std::to_string(kMinViews) + " to " + std::to_string(kMaxViews);
    if (!(viewTimeoutS >= 1.0 && viewTimeoutS <= kMaxViewTimeoutS))
        return "view_timeout_s: must be from 1 to " + std::to_string(int(kMaxViewTimeoutS)) + " s";
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

CalibrationOutcome runCalibration(const std::vector<CalibrationStep>& steps,
                                  const CalibrationOptions& options,
                                  const std::optional<core::Calibration>& start, cv::Size projectorSize,
                                  const CaptureFunction& capture, const ShowFunction& show,
                                  const ProgressFunction& progress) {
    CalibrationOutcome outcome;
    std::optional<core::Calibration> current = start;
    cv::Mat scene;
    const double stepShare = 1.0 / static_cast<double>(steps.size());
    for (std::size_t i = 0; i < steps.size(); ++i) {
        const CalibrationStep& step = steps[i];
        const double begun = stepShare * static_cast<double>(i);
        const StepContext context{options,
                                  current,
                                  projectorSize,
                                  capture,
                                  show,
                                  [&](double fraction, const std::string& message) {
                                      progress(step.name, begun + stepShare * std::clamp(fraction, 0.0, 1.0),
                                               message);
                                  },
                                  scene};
        EstimateResult result = step.run(context);
        if (!result.ok()) {
            outcome.message = "the " + step.name + " step failed: " + result.failure().message;
            return outcome;
        }
        outcome.rmsPx = std::max(outcome.rmsPx, result->rmsPx);
        current = std::move(result->calibration);
        scene = result->scene;
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
