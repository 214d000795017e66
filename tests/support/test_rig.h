#pragma once

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

}  // namespace everytouch::test
