#pragma once

#include "service/calibration_job.h"

namespace everytouch::service {

// The "projector" calibration step: the one-time calibration of the rigid projector-camera pair as a
// dialogue. The projector shows the table set-up's chessboard; progress messages ask for the card on the
// table, then for a board tilted another way with the card on it, options.views poses in all; each pose is
// taken by itself once the scene has held still, the board and the card are found, and the surface is tilted
// away from every pose before (PoseCapture). The pair follows from all poses
// (core::calibrateProjectorCameraPair), the table's pose from the first (core::setUpTable), and the display
// is fitted into the lit area; the estimate's scene is the last pose's still texture. Fails, saying what was
// missing, when no new pose comes within options.viewTimeoutS of camera time.
EstimateResult calibrateProjectorCameraPairStep(const StepContext& context);

}  // namespace everytouch::service
