#pragma once

#include <vector>

#include <Eigen/Geometry>

#include "core/calibration.h"
#include "core/registration_check.h"
#include "core/result.h"

namespace everytouch::core {

// Where a camera that moved now stands, from the code on the table.
struct CameraRelocation {
    Eigen::Isometry3d tableToCamera = Eigen::Isometry3d::Identity();
    // How well the new pose explains the tiles: the RMS distance, camera pixels, between each tile's
    // observed place and where the pose puts its table point.
    double residualPx = 0.0;
    int tiles = 0;  // the tiles it rests on
};

// A camera knocked, a tripod sagged: the projector and the table have not moved against each other, so the
// table point the projector lights through each tile's predicted code is where the calibration says, and the
// camera now sees it at the tile's centre plus its measured shift (RegistrationCheck). The camera's pose
// against the table is estimated from those correspondences (perspective-n-point, starting from the
// calibrated pose), the camera's intrinsics kept. Fails, naming why, on fewer than kMinTiles tiles or tiles
// that span less than a third of the camera image each way (the pose would rest on a corner of the table).
Result<CameraRelocation> relocateCamera(const Calibration& calibration, const std::vector<TileShift>& tiles);

inline constexpr int kMinRelocationTiles = 8;

}  // namespace everytouch::core
