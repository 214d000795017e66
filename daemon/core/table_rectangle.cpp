#include "core/table_rectangle.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/edge_profile.h"
#include "core/geometry.h"
#include "core/gray_frame.h"

namespace everytouch::core {

namespace {

using Quad = std::array<Eigen::Vector2d, 4>;

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() * b.y() - a.y() * b.x();
}

Eigen::Vector2d centroid(const Quad& quad) {
    return (quad[0] + quad[1] + quad[2] + quad[3]) / 4.0;
}

struct Line {
    Eigen::Vector2d point;
    Eigen::Vector2d direction;
};

std::optional<Eigen::Vector2d> intersect(const Line& a, const Line& b) {
    const double denominator = cross(a.direction, b.direction);
    if (std::abs(denominator) < 1e-9)
        return std::nullopt;
    return a.point + a.direction * (cross(b.point - a.point, b.direction) / denominator);
}

// The quad with every side moved outwards by offsetPx (inwards when negative), as an integer polygon.
std::vector<cv::Point> offsetPolygon(const Quad& quad, double offsetPx) {
    const Eigen::Vector2d centre = centroid(quad);
    std::array<Line, 4> sides;
    for (int side = 0; side < 4; ++side) {
        const Eigen::Vector2d along = (quad[(side + 1) % 4] - quad[side]).normalized();
        Eigen::Vector2d outward(along.y(), -along.x());
        if (outward.dot(quad[side] - centre) < 0)
            outward = -outward;
        sides[side] = {quad[side] + outward * offsetPx, along};
    }
    std::vector<cv::Point> polygon;
    for (int corner = 0; corner < 4; ++corner) {
        const Eigen::Vector2d moved =
            intersect(sides[(corner + 3) % 4], sides[corner]).value_or(quad[corner]);
        polygon.emplace_back(static_cast<int>(std::lround(moved.x())),
                             static_cast<int>(std::lround(moved.y())));
    }
    return polygon;
}

// Mean level inside `outer` and outside `inner` (a ring), or inside `outer` alone when inner is empty.
double meanLevel(const cv::Mat& gray, const std::vector<cv::Point>& outer,
                 const std::vector<cv::Point>& inner) {
    const cv::Rect bounds = cv::boundingRect(outer) & cv::Rect(0, 0, gray.cols, gray.rows);
    if (bounds.area() == 0)
        return 0.0;
    cv::Mat mask(bounds.size(), CV_8UC1, cv::Scalar(0));
    cv::fillPoly(mask, std::vector<std::vector<cv::Point>>{outer}, cv::Scalar(255), cv::LINE_8, 0,
                 -bounds.tl());
    if (!inner.empty())
        cv::fillPoly(mask, std::vector<std::vector<cv::Point>>{inner}, cv::Scalar(0), cv::LINE_8, 0,
                     -bounds.tl());
    return cv::mean(gray(bounds), mask)[0];
}

// Four corners of a dark blob's outline, within a few pixels. A rectangle's outline simplifies to four
// vertices; a lens's curvature of long sides may need a coarser simplification, and a blob whose outline does
// not become four vertices is taken as its minimum-area box (the edge refinement sorts out whether it is a
// rectangle).
std::optional<Quad> roughQuad(const std::vector<cv::Point>& contour, const cv::RotatedRect& box,
                              double shortSide) {
    std::vector<cv::Point> polygon;
    Quad rough;
    for (double tolerance = 0.25; tolerance <= 0.6; tolerance *= 1.5) {
        cv::approxPolyDP(contour, polygon, std::max(1.0, tolerance * shortSide), true);
        if (polygon.size() < 4)
            break;
        if (polygon.size() == 4) {
            if (!cv::isContourConvex(polygon))
                return std::nullopt;
            for (int index = 0; index < 4; ++index)
                rough[index] = {polygon[index].x, polygon[index].y};
            return rough;
        }
    }
    std::array<cv::Point2f, 4> corners;
    box.points(corners.data());
    for (int index = 0; index < 4; ++index)
        rough[index] = {corners[index].x, corners[index].y};
    return rough;
}

// The mean side lengths of the two pairs of opposite sides.
std::pair<double, double> oppositeSideLengths(const Quad& quad) {
    return {((quad[1] - quad[0]).norm() + (quad[3] - quad[2]).norm()) / 2.0,
            ((quad[2] - quad[1]).norm() + (quad[0] - quad[3]).norm()) / 2.0};
}

struct EdgeFit {
    Line line;
    double sumSquares = 0.0;
    int points = 0;
};

// Sub-pixel points of the edge from `from` to `to` (raw pixels) of a dark region (the inside is on the side
// of `inside`), undistorted, and a line fitted through them. The ends of the side are skipped.
std::optional<EdgeFit> fitEdge(const cv::Mat& gray, const Eigen::Vector2d& from, const Eigen::Vector2d& to,
                               const Eigen::Vector2d& inside, double reachPx, double minStepDn,
                               const CameraModel& camera) {
    const Eigen::Vector2d along = (to - from).normalized();
    Eigen::Vector2d outward(along.y(), -along.x());
    if (outward.dot(from - inside) < 0)
        outward = -outward;
    const double length = (to - from).norm();
    constexpr double kSkippedEnd = 0.08;  // fraction of the side left out at each end

    std::vector<cv::Point2f> edgePoints;
    for (double position = kSkippedEnd * length; position <= (1.0 - kSkippedEnd) * length; position += 0.5) {
        const Eigen::Vector2d base = from + along * position;
        const std::optional<EdgeCrossing> crossing =
            locateEdgeCrossing(gray, base, outward, reachPx, minStepDn);
        if (!crossing || crossing->stepDn < 0)
            continue;  // no edge, or dark outside
        const Eigen::Vector2d edge = camera.undistortPixel(base + outward * crossing->offsetPx);
        edgePoints.emplace_back(static_cast<float>(edge.x()), static_cast<float>(edge.y()));
    }
    constexpr size_t kMinEdgePoints = 3;
    if (edgePoints.size() < kMinEdgePoints)
        return std::nullopt;

    cv::Vec4f fitted;
    cv::fitLine(edgePoints, fitted, cv::DIST_HUBER, 0, 0.01, 0.01);
    EdgeFit fit;
    fit.line = {{fitted[2], fitted[3]}, Eigen::Vector2d(fitted[0], fitted[1]).normalized()};
    for (const cv::Point2f& point : edgePoints) {
        const double distance = cross(fit.line.direction, Eigen::Vector2d(point.x, point.y) - fit.line.point);
        fit.sumSquares += distance * distance;
    }
    fit.points = static_cast<int>(edgePoints.size());
    return fit;
}

struct RefinedQuad {
    Quad corners;  // cyclic, undistorted pixels
    double edgeRmsPx = 0.0;
};

// One line per side of a quad given in raw pixels, and their intersections.
std::optional<RefinedQuad> refineQuad(const cv::Mat& gray, const Quad& raw, double reachPx, double minStepDn,
                                      const CameraModel& camera) {
    std::array<Line, 4> lines;
    double sumSquares = 0.0;
    int points = 0;
    const Eigen::Vector2d inside = centroid(raw);
    for (int side = 0; side < 4; ++side) {
        const auto fit = fitEdge(gray, raw[side], raw[(side + 1) % 4], inside, reachPx, minStepDn, camera);
        if (!fit)
            return std::nullopt;
        lines[side] = fit->line;
        sumSquares += fit->sumSquares;
        points += fit->points;
    }
    RefinedQuad refined;
    for (int corner = 0; corner < 4; ++corner) {
        const auto point = intersect(lines[(corner + 3) % 4], lines[corner]);
        if (!point)
            return std::nullopt;
        refined.corners[corner] = *point;
    }
    refined.edgeRmsPx = std::sqrt(sumSquares / points);
    return refined;
}

struct Candidate {
    Quad corners;  // cyclic, undistorted pixels
    double edgeRmsPx = 0.0;
    double contrastDn = 0.0;
    double aspectError = 0.0;  // |log| of the side ratio over the true one
};

// Labels the cyclic corners so that corner 0 -> 1 runs along a longer side towards increasing columns and the
// frame (0 -> 1, 0 -> 3) has the handedness of a table frame seen from above (image y points down).
Quad tableOrder(const Quad& cyclic) {
    Quad best = cyclic;
    double bestScore = -std::numeric_limits<double>::infinity();
    for (int start = 0; start < 4; ++start) {
        for (int step : {1, 3}) {
            Quad labelled;
            for (int index = 0; index < 4; ++index)
                labelled[index] = cyclic[(start + step * index) % 4];
            const Eigen::Vector2d xAxis = labelled[1] - labelled[0], yAxis = labelled[3] - labelled[0];
            const auto [first, second] = oppositeSideLengths(labelled);
            if (cross(xAxis, yAxis) >= 0 || first < second)
                continue;
            if (xAxis.x() > bestScore) {
                bestScore = xAxis.x();
                best = labelled;
            }
        }
    }
    return best;
}

}  // namespace

std::optional<std::string> TableRectangleOptions::validate() const {
    if (!(sizeMm.width > 0) || !(sizeMm.height > 0))
        return "rectangle size_mm: both sides must be positive";
    if (sizeMm.width < sizeMm.height)
        return "rectangle size_mm: give the longer side first";
    if (!(maxViewAngleDeg > 0 && maxViewAngleDeg < 90))
        return "rectangle max_view_angle_deg: must be between 0 and 90";
    if (!(minContrastDn > 0))
        return "rectangle min_contrast_dn: must be positive";
    if (!(minSidePx >= 3))
        return "rectangle min_side_px: must be at least 3";
    return std::nullopt;
}

Result<TableRectangleDetection> findTableRectangle(const cv::Mat& cameraImage,
                                                   const TableRectangleOptions& options,
                                                   const CameraModel& camera) {
    if (auto problem = options.validate())
        throw std::invalid_argument("TableRectangleOptions: " + *problem);
    cv::Mat gray;
    if (const Status frame = grayFrame(cameraImage, gray); !frame.ok())
        return frame.failure();
    TableRectangleDetection detection;

    // Dark against the local surroundings. The window spans a quarter of the frame, several times a stripe's
    // width; a larger dark rectangle shows up as a ring whose outline is still the rectangle.
    const int window = (std::min(gray.cols, gray.rows) / 4) | 1;
    cv::Mat dark;
    cv::adaptiveThreshold(gray, dark, 255, cv::ADAPTIVE_THRESH_MEAN_C, cv::THRESH_BINARY_INV, window,
                          options.minContrastDn / 2.0);
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(dark, contours, cv::RETR_LIST, cv::CHAIN_APPROX_NONE);

    const double expectedAspect = options.sizeMm.width / options.sizeMm.height;
    const double maxAspectError = -std::log(std::cos(options.maxViewAngleDeg * M_PI / 180.0));
    std::vector<Candidate> candidates;
    for (const std::vector<cv::Point>& contour : contours) {
        if (cv::contourArea(contour) < options.minSidePx * options.minSidePx)
            continue;
        const cv::RotatedRect box = cv::minAreaRect(contour);
        const double shortSide = std::min(box.size.width, box.size.height);
        if (shortSide < options.minSidePx)
            continue;
        const std::optional<Quad> outline = roughQuad(contour, box, shortSide);
        if (!outline)
            continue;
        const Quad& rough = *outline;
        const auto aspectError = [&](const Quad& quad) {
            const auto [first, second] = oppositeSideLengths(quad);
            return std::abs(std::log(std::max(first, second) / std::min(first, second) / expectedAspect));
        };
        // The outline's vertices cut the corners; its bounding box gives the better first guess of the shape.
        const double boxAspect = std::max(box.size.width, box.size.height) / shortSide;
        if (std::abs(std::log(boxAspect / expectedAspect)) > maxAspectError)
            continue;

        // Outlines of the threshold mask are a pixel or two off the real edges: search across them within a
        // third of the shorter side, enough to cover that and never reach the opposite edge.
        const double reachPx = std::clamp(shortSide / 3.0, 2.0, 8.0);
        const double ringPx = std::max(3.0, shortSide / 2.0);
        const double contrast = meanLevel(gray, offsetPolygon(rough, ringPx), offsetPolygon(rough, 2.0)) -
                                meanLevel(gray, offsetPolygon(rough, -2.0), {});
        if (contrast < options.minContrastDn)
            continue;

        // Twice: the second pass centres the profiles on the edges the first one found.
        std::optional<RefinedQuad> refined =
            refineQuad(gray, rough, reachPx, options.minContrastDn / 2.0, camera);
        if (refined) {
            Quad raw;
            for (int corner = 0; corner < 4; ++corner)
                raw[corner] = camera.distortPixel(refined->corners[corner]);
            refined = refineQuad(gray, raw, reachPx, options.minContrastDn / 2.0, camera);
        }
        if (!refined)
            continue;
        Candidate candidate;
        candidate.corners = refined->corners;
        candidate.aspectError = aspectError(candidate.corners);
        if (candidate.aspectError > maxAspectError)
            continue;
        candidate.edgeRmsPx = refined->edgeRmsPx;
        candidate.contrastDn = contrast;
        const bool duplicate = std::any_of(candidates.begin(), candidates.end(), [&](const Candidate& other) {
            return (centroid(other.corners) - centroid(candidate.corners)).norm() < options.minSidePx;
        });
        if (!duplicate)
            candidates.push_back(candidate);
    }

    detection.candidates = static_cast<int>(candidates.size());
    if (candidates.empty()) {
        char message[128];
        std::snprintf(message, sizeof message, "no dark rectangle of %.1f x %.1f mm in the camera frame",
                      options.sizeMm.width, options.sizeMm.height);
        return Failure{message};
    }
    const Candidate& best =
        *std::min_element(candidates.begin(), candidates.end(),
                          [](const auto& a, const auto& b) { return a.aspectError < b.aspectError; });

    detection.corners = tableOrder(best.corners);
    const double w = options.sizeMm.width, h = options.sizeMm.height;
    detection.tableToCamera =
        fitHomography({{0, 0}, {w, 0}, {w, h}, {0, h}}, {detection.corners.begin(), detection.corners.end()});
    detection.edgeRmsPx = best.edgeRmsPx;
    detection.contrastDn = best.contrastDn;
    return detection;
}

}  // namespace everytouch::core
