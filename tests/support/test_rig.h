#pragma once

#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

#include "core/calibration.h"
#include "io/rig_description.h"

namespace everytouch::test {

// A rig like the paper's: camera 648x488 with a 6 mm lens and 7.4 um pixels, projector 640x480, both about
// 500 mm above the table, looking down at an angle, a few centimetres apart; a 1280x960 display filling the
// panel.
core::Calibration paperLikeCalibration();

// The calibration above, a random binary pattern of projector size and delta 10.
io::RigDescription paperLikeRig(unsigned seed = 1);

// paperLikeCalibration with a lens that bends lines by a few pixels towards the frame's edges (k1 = -0.12,
// k2 = 0.08): the rig the calibration estimators are measured on.
core::Calibration distortedPaperLikeCalibration();

// A plain board lifted by liftMm and tilted by tiltDeg about an axis in the table at axisDeg from the table's
// x axis, through the middle of the area the projector lights; the identity is the table itself.
Eigen::Isometry3d tiltedBoard(double axisDeg, double tiltDeg, double liftMm);

// The table and five tilts of the board, the pair calibration procedure of docs/calibration.md.
std::vector<Eigen::Isometry3d> calibrationPoses();

}  // namespace everytouch::test
