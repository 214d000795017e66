#pragma once

#include <optional>
#include <string>

#include "core/calibration.h"
#include "core/camera_model.h"
#include "core/plane_view.h"
#include "core/projector_chessboard.h"
#include "support/surface_renderer.h"

namespace everytouch::test {

struct CapturedView {
    core::PlaneView view;
    std::string failure;  // what was not found, when something was not
};

// What a calibration sees of one surface: a camera frame of the projected chessboard (its corners pair camera
// and projector pixels) and, when `rectangle` is given, a second frame under white light with the rectangle
// on the surface, found by findTableRectangle. Both rendered through `surfaceRig` with noiseSigmaDn of sensor
// noise. Rectangle corners are fitted in undistorted pixels of `knownCamera` and reported raw.
CapturedView captureView(const core::Calibration& surfaceRig, const std::optional<DarkRectangle>& rectangle,
                         double noiseSigmaDn, unsigned seed, const core::CameraModel& knownCamera = {},
                         const core::ChessboardOptions& chessboard = {});

}  // namespace everytouch::test
