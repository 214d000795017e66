#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "core/camera_model.h"
#include "core/result.h"

namespace everytouch::core {

// The chessboard the projector shows so that the camera can find where projector pixels land (paper Section
// IV: H_CP from a projected chessboard).
struct ChessboardOptions {
    // Inner corners across and down. Their sum must be odd: the board then differs from itself turned half
    // round, so the camera can tell which corner is which.
    cv::Size innerCorners{9, 6};
    // Edge of one square, projector pixels. The board is centred on the panel with white around it.
    int squarePx = 56;
    // Least step between a black and a white square in the camera frame for an edge to count when the corners
    // are refined, digital levels. A projected board on a light table steps by 100 DN or more.
    double minEdgeStepDn = 20.0;
    // A corner further than this from the homography the other corners agree on is an outlier (camera
    // pixels). Sub-pixel corners of a flat board agree to about 0.1 px.
    double maxCornerErrorPx = 1.0;

    // The first problem for a panel of projectorSize; nothing when usable.
    std::optional<std::string> validate(cv::Size projectorSize) const;
};

// The projector image: the board on white, 8-bit gray, projectorSize. Reallocated only on a size change.
// Throws std::invalid_argument when options.validate(projectorSize) fails.
void renderProjectorChessboard(const ChessboardOptions& options, cv::Size projectorSize, cv::Mat& image);

// The board's inner corners in projector pixels (pixel centres at integers), row by row from the top left.
std::vector<Eigen::Vector2d> projectorChessboardCorners(const ChessboardOptions& options,
                                                        cv::Size projectorSize);

// Camera <-> projector correspondences from a camera frame of the projected board.
struct ChessboardDetection {
    std::vector<Eigen::Vector2d> cameraCorners;     // raw camera pixels, sub-pixel
    std::vector<Eigen::Vector2d> projectorCorners;  // the same corners on the projector panel
};

// Finds the board in an 8-bit gray or BGR camera frame. A frame without a board fails within milliseconds.
// Throws std::invalid_argument when options.validate(projectorSize) fails.
Result<ChessboardDetection> detectProjectedChessboard(const cv::Mat& cameraImage,
                                                      const ChessboardOptions& options,
                                                      cv::Size projectorSize);

// H_CP: projector pixels -> undistorted camera pixels, for a board on one plane.
struct ProjectorToCameraEstimate {
    Eigen::Matrix3d homography = Eigen::Matrix3d::Identity();
    double rmsPx = 0.0;  // corner reprojection error of the inliers, camera pixels
    int inliers = 0;
    ChessboardDetection detection;
};

// Detects the board and fits H_CP robustly (RANSAC, then least squares on the inliers) to the corners
// undistorted with `camera`. Fails when the board is not found or fewer than half of its corners agree on one
// plane.
Result<ProjectorToCameraEstimate> estimateProjectorToCamera(const cv::Mat& cameraImage,
                                                            const ChessboardOptions& options,
                                                            cv::Size projectorSize,
                                                            const CameraModel& camera);

}  // namespace everytouch::core
