#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "core/calibration.h"
#include "support/process.h"

namespace everytouch::test {

// Worst distance between the camera pixel -> projector pixel maps of two calibrations on the table, over the
// camera pixels the projector lights (a grid of projector pixels 40 apart), projector pixels.
double worstCameraToProjectorPx(const core::Calibration& found, const core::Calibration& truth);

// `truth` after the table moved under the unchanged projector-camera pair: 40 mm further away, shifted by
// (12, -5) mm and tilted 5 degrees, as a stored calibration is after the rig was knocked.
core::Calibration withTheTableMoved(const core::Calibration& truth);

// The RMS reprojection error everytouch-calib prints after a calibration, px; nothing when it printed none.
std::optional<double> reportedRmsPx(const std::string& toolOutput);

// The checks of `everytouch-calib calibrate table` (`tool`) run from the calibration `moved` from `truth`
// (withTheTableMoved): it succeeded with an RMS error of 0.5 px or less, the calibration it saved in `saved`
// maps camera to projector within 0.5 projector px of the truth, and `moved` was more than 2 px off. Records
// rms_px, worst_camera_to_projector_px and stored_worst_camera_to_projector_px.
void expectTheTableFound(const ProcessResult& tool, const std::filesystem::path& saved,
                         const core::Calibration& moved, const core::Calibration& truth);

}  // namespace everytouch::test
