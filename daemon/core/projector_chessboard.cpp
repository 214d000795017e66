#include "core/projector_chessboard.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/edge_profile.h"
#include "core/gray_frame.h"

namespace everytouch::core {

namespace {

cv::Size squareCount(const ChessboardOptions& options) {
    return {options.innerCorners.width + 1, options.innerCorners.height + 1};
}

// Top-left pixel of the board on the panel.
cv::Point boardOrigin(const ChessboardOptions& options, cv::Size projectorSize) {
    const cv::Size squares = squareCount(options);
    return {(projectorSize.width - squares.width * options.squarePx) / 2,
            (projectorSize.height - squares.height * options.squarePx) / 2};
}

// Square (column, row) is black when column + row is even: the top-left square is black.
bool isBlack(int column, int row) {
    return (column + row) % 2 == 0;
}

std::vector<cv::Point2f> toPoint2f(const std::vector<Eigen::Vector2d>& points) {
    std::vector<cv::Point2f> converted;
    converted.reserve(points.size());
    for (const Eigen::Vector2d& point : points)
        converted.emplace_back(static_cast<float>(point.x()), static_cast<float>(point.y()));
    return converted;
}

Eigen::Matrix3d toEigen(const cv::Mat& homography) {
    Eigen::Matrix3d converted;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            converted(r, c) = homography.at<double>(r, c);
    return converted;
}

// The classic finder reports the corners row by row but may start from any corner of the board. The four
// readings of a rows x columns grid, as maps from the finder's index to the board's index.
enum class Reading { AsIs, HalfTurn, MirroredAcross, MirroredDown };

int boardIndex(Reading reading, int index, cv::Size inner) {
    int column = index % inner.width, row = index / inner.width;
    if (reading == Reading::HalfTurn || reading == Reading::MirroredAcross)
        column = inner.width - 1 - column;
    if (reading == Reading::HalfTurn || reading == Reading::MirroredDown)
        row = inner.height - 1 - row;
    return row * inner.width + column;
}

// How much brighter the white squares look than the black ones when the board is read this way; negative or
// not a number when the reading mirrors the board (a camera and a projector in front of the same surface see
// it with the same handedness).
double readingContrast(const cv::Mat& gray, const std::vector<cv::Point2f>& cameraCorners,
                       const std::vector<Eigen::Vector2d>& boardCorners, Reading reading,
                       const ChessboardOptions& options, cv::Size projectorSize) {
    std::vector<cv::Point2f> projector(cameraCorners.size());
    for (size_t index = 0; index < cameraCorners.size(); ++index) {
        const Eigen::Vector2d& corner =
            boardCorners[boardIndex(reading, static_cast<int>(index), options.innerCorners)];
        projector[index] = {static_cast<float>(corner.x()), static_cast<float>(corner.y())};
    }
    const cv::Mat fitted = cv::findHomography(projector, cameraCorners, 0);
    if (fitted.empty())
        return std::numeric_limits<double>::quiet_NaN();
    const Eigen::Matrix3d homography = toEigen(fitted);

    const cv::Size squares = squareCount(options);
    const cv::Point origin = boardOrigin(options, projectorSize);
    const Eigen::Vector2d centre(origin.x + squares.width * options.squarePx / 2.0 - 0.5,
                                 origin.y + squares.height * options.squarePx / 2.0 - 0.5);
    const Eigen::Vector3d image = homography * centre.homogeneous();
    Eigen::Matrix<double, 2, 2> jacobian;
    jacobian << homography(0, 0) - image.x() / image.z() * homography(2, 0),
        homography(0, 1) - image.x() / image.z() * homography(2, 1),
        homography(1, 0) - image.y() / image.z() * homography(2, 0),
        homography(1, 1) - image.y() / image.z() * homography(2, 1);
    if (!(jacobian.determinant() > 0))
        return std::numeric_limits<double>::quiet_NaN();

    double white = 0, black = 0;
    for (int row = 0; row < squares.height; ++row) {
        for (int column = 0; column < squares.width; ++column) {
            const Eigen::Vector2d squareCentre(origin.x + (column + 0.5) * options.squarePx - 0.5,
                                               origin.y + (row + 0.5) * options.squarePx - 0.5);
            const double level =
                sampleBilinear(gray, (homography * squareCentre.homogeneous()).hnormalized());
            (isBlack(column, row) ? black : white) += level;
        }
    }
    const int squareTotal = squares.area();
    const int blackCount = (squareTotal + 1) / 2;
    return white / (squareTotal - blackCount) - black / blackCount;
}

// Sub-pixel points on the edge from `corner` towards `neighbour` (its middle part, clear of both corners'
// other edges), appended to `points`.
void collectHalfEdge(const cv::Mat& gray, const Eigen::Vector2d& corner, const Eigen::Vector2d& neighbour,
                     double minStepDn, std::vector<cv::Point2f>& points) {
    const double length = (neighbour - corner).norm();
    if (length < 4.0)
        return;
    const Eigen::Vector2d along = (neighbour - corner) / length;
    const Eigen::Vector2d across(-along.y(), along.x());
    const double reachPx = std::clamp(0.2 * length, 1.5, 6.0);
    for (double position = 0.3 * length; position <= 0.7 * length; position += 0.5) {
        const Eigen::Vector2d base = corner + along * position;
        if (const auto crossing = locateEdgeCrossing(gray, base, across, reachPx, minStepDn)) {
            const Eigen::Vector2d point = base + across * crossing->offsetPx;
            points.emplace_back(static_cast<float>(point.x()), static_cast<float>(point.y()));
        }
    }
}

// Moves each corner to the intersection of the two grid lines through it, each fitted to sub-pixel edge
// points on the half-edges either side of the corner: over two squares the lines are straight even through a
// distorting lens. cornerSubPix leaves about 0.08 px of scatter on a board seen in perspective; this about
// 0.02 px. A corner on the board's border uses the edge against the white surround where there is one.
void refineCornersOnEdges(const cv::Mat& gray, cv::Size inner, double minStepDn,
                          std::vector<cv::Point2f>& corners) {
    const std::vector<cv::Point2f> found = corners;
    const auto at = [&](int column, int row) {
        const cv::Point2f& point = found[row * inner.width + column];
        return Eigen::Vector2d(point.x, point.y);
    };
    std::vector<cv::Point2f> points;
    for (int row = 0; row < inner.height; ++row) {
        for (int column = 0; column < inner.width; ++column) {
            const Eigen::Vector2d corner = at(column, row);
            std::array<cv::Vec4f, 2> lines;
            bool complete = true;
            for (int axis = 0; axis < 2 && complete; ++axis) {
                const bool across = axis == 0;
                const int index = across ? column : row, count = across ? inner.width : inner.height;
                const auto neighbour = [&](int other) { return across ? at(other, row) : at(column, other); };
                const Eigen::Vector2d before =
                    index > 0 ? neighbour(index - 1) : 2.0 * corner - neighbour(index + 1);
                const Eigen::Vector2d after =
                    index + 1 < count ? neighbour(index + 1) : 2.0 * corner - neighbour(index - 1);
                points.clear();
                collectHalfEdge(gray, corner, before, minStepDn, points);
                collectHalfEdge(gray, corner, after, minStepDn, points);
                constexpr size_t kMinPoints = 6;
                complete = points.size() >= kMinPoints;
                if (complete)
                    cv::fitLine(points, lines[axis], cv::DIST_HUBER, 0, 0.01, 0.01);
            }
            if (!complete)
                continue;
            const Eigen::Vector2d direction0(lines[0][0], lines[0][1]), point0(lines[0][2], lines[0][3]);
            const Eigen::Vector2d direction1(lines[1][0], lines[1][1]), point1(lines[1][2], lines[1][3]);
            const double denominator = direction0.x() * direction1.y() - direction0.y() * direction1.x();
            if (std::abs(denominator) < 0.1)
                continue;  // nearly parallel: not a corner
            const Eigen::Vector2d offset = point1 - point0;
            const double s = (offset.x() * direction1.y() - offset.y() * direction1.x()) / denominator;
            const Eigen::Vector2d refined = point0 + s * direction0;
            constexpr double kMaxShiftPx =
                1.0;  // the line fit corrects sub-pixel errors, never moves a corner far
            if ((refined - corner).norm() < kMaxShiftPx)
                corners[row * inner.width + column] = {static_cast<float>(refined.x()),
                                                       static_cast<float>(refined.y())};
        }
    }
}

}  // namespace

std::optional<std::string> ChessboardOptions::validate(cv::Size projectorSize) const {
    if (innerCorners.width < 2 || innerCorners.height < 2)
        return "chessboard inner_corners: need at least 2 x 2";
    if ((innerCorners.width + innerCorners.height) % 2 == 0)
        return "chessboard inner_corners: across + down must be odd, or the board looks the same turned half "
               "round";
    if (squarePx < 4)
        return "chessboard square_px: must be at least 4";
    const cv::Size squares = squareCount(*this);
    if (squares.width * squarePx + squarePx > projectorSize.width ||
        squares.height * squarePx + squarePx > projectorSize.height)
        return "chessboard square_px: the board and a white border of half a square do not fit the projector";
    if (!(minEdgeStepDn > 0))
        return "chessboard min_edge_step_dn: must be positive";
    if (!(maxCornerErrorPx > 0))
        return "chessboard max_corner_error_px: must be positive";
    return std::nullopt;
}

void renderProjectorChessboard(const ChessboardOptions& options, cv::Size projectorSize, cv::Mat& image) {
    if (auto problem = options.validate(projectorSize))
        throw std::invalid_argument("ChessboardOptions: " + *problem);
    image.create(projectorSize, CV_8UC1);
    image.setTo(cv::Scalar(255));
    const cv::Size squares = squareCount(options);
    const cv::Point origin = boardOrigin(options, projectorSize);
    for (int row = 0; row < squares.height; ++row)
        for (int column = 0; column < squares.width; ++column)
            if (isBlack(column, row))
                image(cv::Rect(origin.x + column * options.squarePx, origin.y + row * options.squarePx,
                               options.squarePx, options.squarePx))
                    .setTo(cv::Scalar(0));
}

std::vector<Eigen::Vector2d> projectorChessboardCorners(const ChessboardOptions& options,
                                                        cv::Size projectorSize) {
    const cv::Point origin = boardOrigin(options, projectorSize);
    std::vector<Eigen::Vector2d> corners;
    corners.reserve(options.innerCorners.area());
    // A corner sits on the boundary between pixels: half a pixel before the first pixel of the next square.
    for (int row = 1; row <= options.innerCorners.height; ++row)
        for (int column = 1; column <= options.innerCorners.width; ++column)
            corners.emplace_back(origin.x + column * options.squarePx - 0.5,
                                 origin.y + row * options.squarePx - 0.5);
    return corners;
}

Result<ChessboardDetection> detectProjectedChessboard(const cv::Mat& cameraImage,
                                                      const ChessboardOptions& options,
                                                      cv::Size projectorSize) {
    if (auto problem = options.validate(projectorSize))
        throw std::invalid_argument("ChessboardOptions: " + *problem);
    cv::Mat gray;
    if (const Status frame = grayFrame(cameraImage, gray); !frame.ok())
        return frame.failure();

    std::vector<cv::Point2f> corners;
    // Without the fast check the finder spends seconds on a frame that has no board.
    const int flags = cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK;
    if (!cv::findChessboardCorners(gray, options.innerCorners, corners, flags))
        return Failure{"no projected chessboard of " + std::to_string(options.innerCorners.width) + " x " +
                       std::to_string(options.innerCorners.height) + " inner corners in the camera frame"};

    // The refinement window must stay inside the four squares around a corner.
    double spacing = std::numeric_limits<double>::infinity();
    const cv::Size inner = options.innerCorners;
    for (int index = 0; index < static_cast<int>(corners.size()); ++index) {
        if (index % inner.width + 1 < inner.width)
            spacing = std::min(spacing, static_cast<double>(cv::norm(corners[index + 1] - corners[index])));
        if (index + inner.width < static_cast<int>(corners.size()))
            spacing = std::min(spacing,
                               static_cast<double>(cv::norm(corners[index + inner.width] - corners[index])));
    }
    const int halfWindow = std::clamp(static_cast<int>(spacing * 0.3), 2, 15);
    cv::cornerSubPix(gray, corners, {halfWindow, halfWindow}, {-1, -1},
                     cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 50, 1e-3));
    // Twice: the second pass samples edges found from better corners.
    for (int pass = 0; pass < 2; ++pass)
        refineCornersOnEdges(gray, inner, options.minEdgeStepDn, corners);

    const std::vector<Eigen::Vector2d> boardCorners = projectorChessboardCorners(options, projectorSize);
    std::optional<Reading> best;
    double bestContrast = 0.0;
    for (Reading reading :
         {Reading::AsIs, Reading::HalfTurn, Reading::MirroredAcross, Reading::MirroredDown}) {
        const double contrast = readingContrast(gray, corners, boardCorners, reading, options, projectorSize);
        if (contrast > bestContrast) {
            bestContrast = contrast;
            best = reading;
        }
    }
    if (!best)
        return Failure{"projected chessboard: cannot tell its black squares from its white ones"};

    ChessboardDetection detection;
    detection.cameraCorners.reserve(corners.size());
    detection.projectorCorners.reserve(corners.size());
    for (size_t index = 0; index < corners.size(); ++index) {
        detection.cameraCorners.emplace_back(corners[index].x, corners[index].y);
        detection.projectorCorners.push_back(boardCorners[boardIndex(*best, static_cast<int>(index), inner)]);
    }
    return detection;
}

Result<ProjectorToCameraEstimate> estimateProjectorToCamera(const cv::Mat& cameraImage,
                                                            const ChessboardOptions& options,
                                                            cv::Size projectorSize,
                                                            const CameraModel& camera) {
    Result<ChessboardDetection> detection = detectProjectedChessboard(cameraImage, options, projectorSize);
    if (!detection.ok())
        return detection.failure();
    ProjectorToCameraEstimate estimate;
    estimate.detection = std::move(detection).value();
    std::vector<Eigen::Vector2d> undistorted;
    undistorted.reserve(estimate.detection.cameraCorners.size());
    for (const Eigen::Vector2d& corner : estimate.detection.cameraCorners)
        undistorted.push_back(camera.undistortPixel(corner));
    const std::vector<cv::Point2f> projector = toPoint2f(estimate.detection.projectorCorners);
    const std::vector<cv::Point2f> cameraPoints = toPoint2f(undistorted);
    std::vector<uchar> inlierMask;
    const cv::Mat fitted =
        cv::findHomography(projector, cameraPoints, cv::RANSAC, options.maxCornerErrorPx, inlierMask);
    const int total = static_cast<int>(projector.size());
    estimate.inliers = static_cast<int>(std::count(inlierMask.begin(), inlierMask.end(), 1));
    if (fitted.empty() || 2 * estimate.inliers < total)
        return Failure{"projected chessboard: only " + std::to_string(estimate.inliers) + " of " +
                       std::to_string(total) + " corners agree on one plane"};
    estimate.homography = toEigen(fitted);
    double sumSquares = 0.0;
    for (int index = 0; index < total; ++index) {
        if (!inlierMask[index])
            continue;
        const Eigen::Vector2d predicted =
            (estimate.homography * estimate.detection.projectorCorners[index].homogeneous()).hnormalized();
        sumSquares += (predicted - undistorted[index]).squaredNorm();
    }
    estimate.rmsPx = std::sqrt(sumSquares / estimate.inliers);
    return estimate;
}

}  // namespace everytouch::core
