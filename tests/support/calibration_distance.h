#pragma once

#include "core/calibration.h"

namespace everytouch::test {

// Worst distance between the camera pixel -> projector pixel maps of two calibrations on the table, over the
// camera pixels the projector lights (a grid of projector pixels 40 apart), projector pixels.
double worstCameraToProjectorPx(const core::Calibration& found, const core::Calibration& truth);

}  // namespace everytouch::test
