#include "core/table_setup.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <Eigen/SVD>
#include <unsupported/Eigen/LevenbergMarquardt>
#include <unsupported/Eigen/NumericalDiff>

#include "core/geometry.h"
#include "core/plane_triangulation.h"

namespace everytouch::core {

namespace {

// Parameters: the table's rotation vector and translation into the camera frame.
Eigen::Isometry3d tablePose(const Eigen::VectorXd& parameters) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = rotationFromVector(parameters.head<3>());
    pose.translation() = parameters.tail<3>();
    return pose;
}

struct TablePoseResiduals : Eigen::DenseFunctor<double> {
    TablePoseResiduals(const ProjectorCameraPair& pair, const PlaneView& view, cv::Size2d rectangleSizeMm)
        : Eigen::DenseFunctor<double>(6, residualCount(view)),
          pair_(&pair),
          view_(&view),
          rectangleSizeMm_(rectangleSizeMm) {}

    int operator()(const Eigen::VectorXd& parameters, Eigen::VectorXd& residuals) const {
        const Eigen::Isometry3d tableToCamera = tablePose(parameters);
        planeViewResiduals(*pair_, planeOf(tableToCamera), *view_, tableToCamera, rectangleSizeMm_,
                           residuals.data());
        return 0;
    }

    const ProjectorCameraPair* pair_;
    const PlaneView* view_;
    cv::Size2d rectangleSizeMm_;
};

}  // namespace

std::optional<std::string> TableSetupOptions::validate() const {
    if (!(rectangleSizeMm.width > 0) || !(rectangleSizeMm.height > 0))
        return "rectangle size_mm: both sides must be positive";
    if (!(maxRmsPx > 0))
        return "max_rms_px: must be positive";
    return std::nullopt;
}

Result<TableSetup> setUpTable(const ProjectorCameraPair& pair, const PlaneView& table,
                              const TableSetupOptions& options) {
    if (auto problem = options.validate())
        throw std::invalid_argument("TableSetupOptions: " + *problem);
    if (!table.rectangleCorners)
        return Failure{"table view: the rectangle was not found on the table"};
    if (table.cameraPoints.size() != table.projectorPoints.size() || table.cameraPoints.size() < 3)
        return Failure{
            "table view: need at least three camera <-> projector correspondences, as many of each"};

    const std::optional<Eigen::Hyperplane<double, 3>> plane = triangulatePlane(pair, table);
    if (!plane)
        return Failure{"table view: the correspondences do not span a plane in front of the camera"};
    const std::optional<Eigen::Isometry3d> initial =
        rectangleOnPlane(pair.camera, *plane, *table.rectangleCorners, options.rectangleSizeMm);
    if (!initial)
        return Failure{"table view: the rectangle's corners are not in table order on the plane"};

    Eigen::VectorXd parameters(6);
    parameters << vectorFromRotation(initial->rotation()), initial->translation();
    Eigen::NumericalDiff<TablePoseResiduals> residuals(
        TablePoseResiduals(pair, table, options.rectangleSizeMm));
    Eigen::LevenbergMarquardt<Eigen::NumericalDiff<TablePoseResiduals>> solver(residuals);
    solver.minimize(parameters);
    TableSetup setup;
    setup.iterations = static_cast<int>(solver.iterations());

    const Eigen::Isometry3d tableToCamera = tablePose(parameters);
    Eigen::VectorXd finalResiduals(residuals.values());
    residuals(parameters, finalResiduals);
    setup.rmsPx = reprojectionRms({table}, finalResiduals);
    setup.calibration = pair.withTable(tableToCamera);
    if (!std::isfinite(setup.rmsPx.all) || setup.rmsPx.all > options.maxRmsPx) {
        char message[160];
        std::snprintf(
            message, sizeof message,
            "table set-up: RMS reprojection error %.2f px exceeds %.2f px (camera %.2f, projector %.2f)",
            setup.rmsPx.all, options.maxRmsPx, setup.rmsPx.camera, setup.rmsPx.projector);
        return Failure{message};
    }
    return setup;
}

}  // namespace everytouch::core
