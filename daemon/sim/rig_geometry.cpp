#include "sim/rig_geometry.h"

#include <algorithm>
#include <array>
#include <stdexcept>

#include "core/geometry.h"

namespace everytouch::sim {

Eigen::Isometry3d aimDevice(const Eigen::Matrix3d& intrinsics, const Eigen::Vector2d& aimPixel,
                            const Eigen::Vector3d& position, const Eigen::Vector3d& target) {
    // Table directions of the aiming ray and of the image axes.
    const Eigen::Vector3d forward = (target - position).normalized();
    Eigen::Vector3d columns = Eigen::Vector3d::UnitX() - forward * forward.x();
    if (columns.norm() < 1e-9)
        throw std::invalid_argument("the device looks along the table's x axis");
    columns.normalize();
    const Eigen::Vector3d rows = forward.cross(columns);
    // The same directions in the device frame: the aiming pixel's ray, the image x axis, and their cross.
    const Eigen::Vector3d deviceForward = (intrinsics.inverse() * aimPixel.homogeneous()).normalized();
    const Eigen::Vector3d deviceColumns =
        (Eigen::Vector3d::UnitX() - deviceForward * deviceForward.x()).normalized();
    const Eigen::Vector3d deviceRows = deviceForward.cross(deviceColumns);
    Eigen::Matrix3d tableAxes, deviceAxes;
    tableAxes << columns, rows, forward;
    deviceAxes << deviceColumns, deviceRows, deviceForward;
    Eigen::Isometry3d deviceToTable = Eigen::Isometry3d::Identity();
    deviceToTable.linear() = tableAxes * deviceAxes.transpose();
    deviceToTable.translation() = position;
    return deviceToTable.inverse();
}

core::Calibration rigCalibration(const SimParameters& p) {
    core::Calibration calibration;
    calibration.cameraSize = p.cameraSize;
    const double cameraFocalPx = p.cameraFocalMm * 1000.0 / p.cameraPixelUm;
    const Eigen::Vector2d cameraCentre((p.cameraSize.width - 1) / 2.0, (p.cameraSize.height - 1) / 2.0);
    calibration.cameraMatrix << cameraFocalPx, 0, cameraCentre.x(), 0, cameraFocalPx, cameraCentre.y(), 0, 0,
        1;
    calibration.tableToCamera =
        aimDevice(calibration.cameraMatrix, cameraCentre, p.cameraPosition, p.cameraTarget);

    calibration.projectorSize = p.projectorSize;
    const Eigen::Vector2d panelCentre((p.projectorSize.width - 1) / 2.0, (p.projectorSize.height - 1) / 2.0);
    calibration.projectorMatrix << p.projectorFocalPx, 0, panelCentre.x(), 0, p.projectorFocalPx,
        p.projectorPrincipalRowPx, 0, 0, 1;
    calibration.tableToProjector =
        aimDevice(calibration.projectorMatrix, panelCentre, p.projectorPosition, p.projectorTarget);

    calibration.displaySize = p.displaySize;
    const double panelW = p.projectorSize.width, panelH = p.projectorSize.height;
    if (!p.keystoneCorrection) {
        calibration.displayToProjector =
            Eigen::Vector3d(panelW / p.displaySize.width, panelH / p.displaySize.height, 1).asDiagonal();
        return calibration;
    }
    // The projected quadrilateral on the table, then the largest rectangle of the display's aspect inside it,
    // oriented for the user at +y: display rows run towards +y, display columns towards -x.
    const Eigen::Matrix3d panelToTable = calibration.tableToProjectorHomography().inverse();
    const Eigen::Vector2d a = core::applyHomography(panelToTable, {0, 0});
    const Eigen::Vector2d b = core::applyHomography(panelToTable, {panelW, 0});
    const Eigen::Vector2d c = core::applyHomography(panelToTable, {panelW, panelH});
    const Eigen::Vector2d d = core::applyHomography(panelToTable, {0, panelH});
    // Inner box of a convex quadrilateral whose edges are roughly axis-aligned: its second-smallest and
    // second-largest coordinates on each axis.
    std::array<double, 4> xs{a.x(), b.x(), c.x(), d.x()}, ys{a.y(), b.y(), c.y(), d.y()};
    std::sort(xs.begin(), xs.end());
    std::sort(ys.begin(), ys.end());
    double left = xs[1], right = xs[2], top = ys[1], bottom = ys[2];
    const double aspect = static_cast<double>(p.displaySize.width) / p.displaySize.height;
    double width = right - left, height = bottom - top;
    if (width / height > aspect) {
        const double shrink = width - height * aspect;
        left += shrink / 2, right -= shrink / 2, width = right - left;
    } else {
        const double shrink = height - width / aspect;
        top += shrink / 2, bottom -= shrink / 2, height = bottom - top;
    }
    const double mmPerPixel = width / p.displaySize.width;
    Eigen::Matrix3d displayToTable;
    displayToTable << -mmPerPixel, 0, right, 0, mmPerPixel, top, 0, 0, 1;
    calibration.displayToProjector = calibration.tableToProjectorHomography() * displayToTable;
    calibration.displayToProjector /= calibration.displayToProjector(2, 2);
    return calibration;
}

}  // namespace everytouch::sim
