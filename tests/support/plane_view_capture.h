#pragma once

#include <optional>

#include "core/calibration.h"
#include "core/camera_model.h"
#include "core/plane_view.h"
#include "core/projector_chessboard.h"
#include "core/result.h"
#include "support/surface_renderer.h"

namespace everytouch::test {

// What a calibration sees of one surface: a camera frame of the projected chessboard (its corners pair camera
// and projector pixels) and, when `rectangle` is given, a second frame under white light with the rectangle
// on the surface, found by findTableRectangle. Both rendered through `surfaceRig` with noiseSigmaDn of sensor
// noise. Rectangle corners are fitted in undistorted pixels of `knownCamera` and reported raw. Fails with
// what was not found.
core::Result<core::PlaneView> captureView(const core::Calibration& surfaceRig,
                                          const std::optional<DarkRectangle>& rectangle, double noiseSigmaDn,
                                          unsigned seed, const core::CameraModel& knownCamera = {},
                                          const core::ChessboardOptions& chessboard = {});

}  // namespace everytouch::test
