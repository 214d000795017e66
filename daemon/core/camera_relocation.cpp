#include "core/camera_relocation.h"

#include <cmath>
#include <string>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "core/camera_model.h"
#include "core/geometry.h"

namespace everytouch::core {

namespace {

// The tiles must span this share of the image's width and of its height.
constexpr double kLeastSpan = 1.0 / 3.0;

}  // namespace

Result<CameraRelocation> relocateCamera(const Calibration& calibration, const std::vector<TileShift>& tiles) {
    if (static_cast<int>(tiles.size()) < kMinRelocationTiles)
        return Failure{"the code was measured on " + std::to_string(tiles.size()) + " tiles of the table, " +
                       std::to_string(kMinRelocationTiles) + " are needed"};
    const CameraModel camera{calibration.cameraMatrix, calibration.cameraDistortion};
    const Eigen::Matrix3d cameraToProjector = calibration.cameraToProjectorHomography();
    const Eigen::Matrix3d projectorToTable = calibration.tableToProjectorHomography().inverse();
    std::vector<cv::Point3d> tablePoints;
    std::vector<cv::Point2d> seen;
    Eigen::Vector2d least = tiles.front().centre, most = least;
    for (const TileShift& tile : tiles) {
        const Eigen::Vector2d lit = applyHomography(cameraToProjector, camera.undistortPixel(tile.centre));
        const Eigen::Vector2d onTable = applyHomography(projectorToTable, lit);
        tablePoints.emplace_back(onTable.x(), onTable.y(), 0.0);
        const Eigen::Vector2d observed = tile.centre + tile.cameraPx;
        seen.emplace_back(observed.x(), observed.y());
        least = least.cwiseMin(observed);
        most = most.cwiseMax(observed);
    }
    const Eigen::Vector2d span = most - least;
    if (span.x() < kLeastSpan * calibration.cameraSize.width ||
        span.y() < kLeastSpan * calibration.cameraSize.height)
        return Failure{"the tiles the code was measured on span " + std::to_string(std::lround(span.x())) +
                       "x" + std::to_string(std::lround(span.y())) +
                       " camera pixels, too little of the table for the camera's pose"};

    cv::Mat cameraMatrix, distortion, rotation, translation;
    cv::eigen2cv(calibration.cameraMatrix, cameraMatrix);
    cv::eigen2cv(calibration.cameraDistortion, distortion);
    Eigen::Matrix3d startRotation = calibration.tableToCamera.linear();
    cv::Mat rotationMatrix;
    cv::eigen2cv(startRotation, rotationMatrix);
    cv::Rodrigues(rotationMatrix, rotation);
    cv::eigen2cv(Eigen::Vector3d(calibration.tableToCamera.translation()), translation);
    if (!cv::solvePnP(tablePoints, seen, cameraMatrix, distortion, rotation, translation, true,
                      cv::SOLVEPNP_ITERATIVE))
        return Failure{"the camera's pose does not follow from the code's place on the table"};

    std::vector<cv::Point2d> projected;
    cv::projectPoints(tablePoints, rotation, translation, cameraMatrix, distortion, projected);
    double squares = 0.0;
    for (std::size_t i = 0; i < seen.size(); ++i) {
        const cv::Point2d d = projected[i] - seen[i];
        squares += d.dot(d);
    }
    cv::Rodrigues(rotation, rotationMatrix);
    CameraRelocation relocation;
    Eigen::Matrix3d turned;
    Eigen::Vector3d moved;
    cv::cv2eigen(rotationMatrix, turned);
    cv::cv2eigen(translation, moved);
    relocation.tableToCamera.linear() = turned;
    relocation.tableToCamera.translation() = moved;
    relocation.residualPx = std::sqrt(squares / static_cast<double>(seen.size()));
    relocation.tiles = static_cast<int>(seen.size());
    return relocation;
}

}  // namespace everytouch::core
