#pragma once

#include <optional>
#include <string>

#include <opencv2/core/types.hpp>

#include "core/calibration.h"
#include "core/plane_view.h"
#include "core/projector_camera_pair.h"
#include "core/result.h"

namespace everytouch::core {

struct TableSetupOptions {
    cv::Size2d rectangleSizeMm{85.5,
                               12.5};  // the dark rectangle on the table, longer side first (card stripe)
    // The set-up fails above this RMS reprojection error (pixels): the pair's calibration no longer fits, or
    // the points are not on one plane.
    double maxRmsPx = 1.0;

    std::optional<std::string> validate() const;
};

struct TableSetup {
    // The pair with the table found: table_to_camera and table_to_projector set, display fields at defaults.
    Calibration calibration;
    ReprojectionRms rmsPx;
    int iterations = 0;
};

// The paper's quick set-up on top of the pair's one-time calibration: camera <-> projector correspondences of
// one pattern projected on the table give the table's plane; the rectangle lying on it gives the table frame:
// origin at the rectangle's (0, 0) corner, x along its longer side, z up towards the camera. The table pose
// is refined by minimising the reprojection errors in both devices. Fails, naming what is wrong, when `table`
// lacks the rectangle's corners or three correspondences, when they do not give a table, and when the RMS
// reprojection error exceeds options.maxRmsPx; throws std::invalid_argument when options.validate() fails.
Result<TableSetup> setUpTable(const ProjectorCameraPair& pair, const PlaneView& table,
                              const TableSetupOptions& options);

}  // namespace everytouch::core
