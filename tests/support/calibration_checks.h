#pragma once

#include <optional>
#include <string>

#include "core/calibration.h"

namespace everytouch::test {

// Worst distance between the camera pixel -> projector pixel maps of two calibrations on the table, over the
// camera pixels the projector lights (a grid of projector pixels 40 apart), projector pixels.
double worstCameraToProjectorPx(const core::Calibration& found, const core::Calibration& truth);

// `truth` after the table moved under the unchanged projector-camera pair: 40 mm further away, shifted by
// (12, -5) mm and tilted 5 degrees, as a stored calibration is after the rig was knocked.
core::Calibration withTheTableMoved(const core::Calibration& truth);

// The RMS reprojection error everytouch-calib prints after a calibration, px; nothing when it printed none.
std::optional<double> reportedRmsPx(const std::string& toolOutput);

}  // namespace everytouch::test
