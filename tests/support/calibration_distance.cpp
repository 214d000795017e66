#include "support/calibration_distance.h"

#include <algorithm>

#include "core/geometry.h"

namespace everytouch::test {

double worstCameraToProjectorPx(const core::Calibration& found, const core::Calibration& truth) {
    double worstPx = 0;
    for (double x = 40; x <= truth.projectorSize.width - 40; x += 40)
        for (double y = 40; y <= truth.projectorSize.height - 40; y += 40) {
            const Eigen::Vector2d camera = core::applyHomography(truth.projectorToCameraHomography(), {x, y});
            if (camera.x() < 0 || camera.y() < 0 || camera.x() > truth.cameraSize.width - 1 ||
                camera.y() > truth.cameraSize.height - 1)
                continue;
            worstPx = std::max(worstPx, (core::applyHomography(found.cameraToProjectorHomography(), camera) -
                                         Eigen::Vector2d(x, y))
                                            .norm());
        }
    return worstPx;
}

}  // namespace everytouch::test
