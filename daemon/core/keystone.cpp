#include "core/keystone.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include <Eigen/LU>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include "core/geometry.h"

namespace everytouch::core {

namespace {

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() * b.y() - a.y() * b.x();
}

}  // namespace

Result<KeystoneFit> fitDisplayToTable(const Calibration& calibration, cv::Size displaySize) {
    if (displaySize.width <= 0 || displaySize.height <= 0)
        return Failure{"display_size: width and height must be positive"};
    if (calibration.projectorSize.width <= 0 || calibration.projectorSize.height <= 0)
        return Failure{"projector_size: width and height must be positive"};

    // The lit quadrilateral: the panel's outer pixel edges on the table.
    const Eigen::Matrix3d tableToProjector = calibration.tableToProjectorHomography();
    const Eigen::Matrix3d projectorToTable = tableToProjector.inverse();
    const double right = calibration.projectorSize.width - 0.5,
                 bottom = calibration.projectorSize.height - 0.5;
    const std::array<Eigen::Vector2d, 4> panel = {Eigen::Vector2d(-0.5, -0.5), Eigen::Vector2d(right, -0.5),
                                                  Eigen::Vector2d(right, bottom),
                                                  Eigen::Vector2d(-0.5, bottom)};
    std::array<Eigen::Vector2d, 4> quad;
    std::array<double, 4> scale;
    for (int index = 0; index < 4; ++index) {
        const Eigen::Vector3d onTable = projectorToTable * panel[index].homogeneous();
        scale[index] = onTable.z();
        quad[index] = onTable.hnormalized();
    }
    if (!(scale[0] * scale[1] > 0 && scale[0] * scale[2] > 0 && scale[0] * scale[3] > 0))
        return Failure{"table_to_projector: part of the projector's image never reaches the table"};
    double orientation = 0;
    for (int index = 0; index < 4; ++index) {
        const double turn =
            cross(quad[(index + 1) % 4] - quad[index], quad[(index + 2) % 4] - quad[(index + 1) % 4]);
        if (index > 0 && !(turn * orientation > 0))
            return Failure{"table_to_projector: the lit area on the table is not a convex quadrilateral"};
        orientation = turn;
    }

    // The display's axes on the table: the table axis closest to the projector's x axis, and the
    // perpendicular axis with the projector's handedness.
    const Eigen::Vector2d centre = applyHomography(projectorToTable, (panel[0] + panel[2]) / 2.0);
    const Eigen::Vector2d projectorXOnTable =
        applyHomography(projectorToTable, (panel[0] + panel[2]) / 2.0 + Eigen::Vector2d(1, 0)) - centre;
    const Eigen::Vector2d projectorYOnTable =
        applyHomography(projectorToTable, (panel[0] + panel[2]) / 2.0 + Eigen::Vector2d(0, 1)) - centre;
    Eigen::Vector2d displayX = Eigen::Vector2d::UnitX();
    for (const Eigen::Vector2d& axis :
         {Eigen::Vector2d(-1, 0), Eigen::Vector2d(0, 1), Eigen::Vector2d(0, -1)})
        if (axis.dot(projectorXOnTable) > displayX.dot(projectorXOnTable))
            displayX = axis;
    Eigen::Vector2d displayY(-displayX.y(), displayX.x());
    if (cross(displayX, displayY) * cross(projectorXOnTable, projectorYOnTable) < 0)
        displayY = -displayY;

    // Largest rectangle [c - h, c + h] with h = w/2 * (|displayX| + |displayY| / aspect) inside every edge of
    // the quad: a linear programme in (c_x, c_y, w). Each edge keeps out the rectangle's corner that reaches
    // furthest across it; the optimum is a vertex where three of the four edge constraints are tight.
    const double aspect = static_cast<double>(displaySize.width) / displaySize.height;
    const Eigen::Vector2d halfExtentPerWidth = (displayX.cwiseAbs() + displayY.cwiseAbs() / aspect) / 2.0;
    Eigen::Matrix<double, 4, 3> constraints;
    Eigen::Vector4d bounds;
    for (int index = 0; index < 4; ++index) {
        const Eigen::Vector2d along = quad[(index + 1) % 4] - quad[index];
        Eigen::Vector2d outward = Eigen::Vector2d(along.y(), -along.x()).normalized();
        if (orientation < 0)
            outward = -outward;
        constraints.row(index) << outward.x(), outward.y(), outward.cwiseAbs().dot(halfExtentPerWidth);
        bounds(index) = outward.dot(quad[index]);
    }
    double bestWidth = 0.0;
    std::vector<Eigen::Vector3d> optima;
    for (int skipped = 0; skipped < 4; ++skipped) {
        Eigen::Matrix3d tight;
        Eigen::Vector3d tightBounds;
        for (int index = 0, row = 0; index < 4; ++index) {
            if (index == skipped)
                continue;
            tight.row(row) = constraints.row(index);
            tightBounds(row++) = bounds(index);
        }
        const Eigen::FullPivLU<Eigen::Matrix3d> lu(tight);
        if (!lu.isInvertible())
            continue;
        const Eigen::Vector3d vertex = lu.solve(tightBounds);
        const double tolerance = 1e-9 * (1.0 + bounds.cwiseAbs().maxCoeff());
        if (!((constraints * vertex - bounds).maxCoeff() <= tolerance) || !(vertex.z() > 0))
            continue;
        if (vertex.z() > bestWidth * (1.0 + 1e-12)) {
            optima.clear();
            bestWidth = vertex.z();
        }
        if (vertex.z() >= bestWidth * (1.0 - 1e-12))
            optima.push_back(vertex);
    }
    if (optima.empty())
        return Failure{"table_to_projector: no rectangle fits inside the lit area"};
    // Several optimal vertices: the optimum is an edge of the feasible set; its middle centres the display.
    Eigen::Vector3d optimum = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& vertex : optima)
        optimum += vertex;
    optimum /= static_cast<double>(optima.size());

    const Eigen::Vector2d rectangleCentre = optimum.head<2>();
    const double millimetresPerPixel = optimum.z() / displaySize.width;
    const Eigen::Vector2d halfExtent = halfExtentPerWidth * optimum.z();
    KeystoneFit fit;
    fit.tableRectangleMm = Eigen::AlignedBox2d(rectangleCentre - halfExtent, rectangleCentre + halfExtent);

    // Display pixel centres sit at integers: the display's outer edges are at -0.5 and size - 0.5.
    const Eigen::Vector2d displayCentre((displaySize.width - 1) / 2.0, (displaySize.height - 1) / 2.0);
    Eigen::Matrix3d displayToTable = Eigen::Matrix3d::Identity();
    displayToTable.block<2, 1>(0, 0) = displayX * millimetresPerPixel;
    displayToTable.block<2, 1>(0, 1) = displayY * millimetresPerPixel;
    displayToTable.block<2, 1>(0, 2) =
        rectangleCentre - millimetresPerPixel * (displayX * displayCentre.x() + displayY * displayCentre.y());
    fit.displayToProjector = tableToProjector * displayToTable;
    fit.displayToProjector /= fit.displayToProjector(2, 2);
    return fit;
}

DisplayShape displayShapeOnTable(const Calibration& calibration) {
    const Eigen::Matrix3d displayToTable = calibration.displayToTableHomography();
    const double w = calibration.displaySize.width, h = calibration.displaySize.height;
    // Clockwise from the top left, on the display's outer pixel edges.
    const std::array<Eigen::Vector2d, 4> corners = {applyHomography(displayToTable, {-0.5, -0.5}),
                                                    applyHomography(displayToTable, {w - 0.5, -0.5}),
                                                    applyHomography(displayToTable, {w - 0.5, h - 0.5}),
                                                    applyHomography(displayToTable, {-0.5, h - 0.5})};
    DisplayShape shape;
    shape.topMm = (corners[1] - corners[0]).norm();
    shape.rightMm = (corners[2] - corners[1]).norm();
    shape.bottomMm = (corners[3] - corners[2]).norm();
    shape.leftMm = (corners[0] - corners[3]).norm();
    shape.leastCornerDeg = 180.0;
    for (int k = 0; k < 4; ++k) {
        const Eigen::Vector2d toNext = corners[(k + 1) % 4] - corners[k];
        const Eigen::Vector2d toPrevious = corners[(k + 3) % 4] - corners[k];
        const double degrees =
            std::acos(std::clamp(toNext.normalized().dot(toPrevious.normalized()), -1.0, 1.0)) * 180.0 / M_PI;
        shape.leastCornerDeg = std::min(shape.leastCornerDeg, degrees);
        shape.largestCornerDeg = std::max(shape.largestCornerDeg, degrees);
    }
    return shape;
}

cv::Mat drawThroughKeystone(const cv::Mat& displayImage, const Eigen::Matrix3d& displayToProjector,
                            cv::Size panelSize) {
    cv::Mat keystone;
    cv::eigen2cv(displayToProjector, keystone);
    cv::Mat image;
    cv::warpPerspective(displayImage, image, keystone, panelSize, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                        cv::Scalar::all(0));
    return image;
}

void checkDisplayToProjector(cv::Size displaySize, const Eigen::Matrix3d& displayToProjector) {
    if (displaySize.width <= 0 || displaySize.height <= 0)
        throw std::invalid_argument("display size: expected a positive width and height");
    if (!displayToProjector.allFinite() || std::abs(displayToProjector.determinant()) < 1e-12 ||
        displayToProjector(2, 2) == 0.0)
        throw std::invalid_argument("display to projector: expected a finite, invertible homography");
}

}  // namespace everytouch::core
