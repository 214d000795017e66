#include "support/test_rig.h"

#include <cmath>

#include <opencv2/core.hpp>

namespace everytouch::test {

namespace {

// A device at `position` (table mm) looking at `target` on the table, image rows running along +y of the
// table.
Eigen::Isometry3d lookAt(const Eigen::Vector3d& position, const Eigen::Vector3d& target) {
    const Eigen::Vector3d forward = (target - position).normalized();
    const Eigen::Vector3d right = Eigen::Vector3d::UnitY().cross(forward).normalized() * -1.0;
    const Eigen::Vector3d down = forward.cross(right);
    Eigen::Matrix3d deviceToTable;
    deviceToTable << right, down, forward;
    Eigen::Isometry3d deviceToTablePose = Eigen::Isometry3d::Identity();
    deviceToTablePose.linear() = deviceToTable;
    deviceToTablePose.translation() = position;
    return deviceToTablePose.inverse();
}

}  // namespace

core::Calibration paperLikeCalibration() {
    core::Calibration calibration;
    calibration.cameraSize = {648, 488};
    const double cameraFocal = 6.0 / 0.0074;  // 6 mm lens, 7.4 um pixels
    calibration.cameraMatrix << cameraFocal, 0, 324, 0, cameraFocal, 244, 0, 0, 1;
    calibration.projectorSize = {640, 480};
    calibration.projectorMatrix << 1350, 0, 320, 0, 1350, 470, 0, 0, 1;
    const Eigen::Vector3d tableCentre(160, 120, 0);
    calibration.tableToCamera = lookAt({160, -120, 460}, tableCentre);
    calibration.tableToProjector = lookAt({200, -110, 470}, tableCentre);
    calibration.displaySize = {1280, 960};
    calibration.displayToProjector = Eigen::Vector3d(0.5, 0.5, 1).asDiagonal();
    return calibration;
}

io::RigDescription paperLikeRig(unsigned seed) {
    io::RigDescription rig;
    rig.calibration = paperLikeCalibration();
    rig.pattern.create(rig.calibration.projectorSize, CV_8UC1);
    cv::RNG rng(seed);
    rng.fill(rig.pattern, cv::RNG::UNIFORM, 0, 2);
    return rig;
}

core::Calibration distortedPaperLikeCalibration() {
    core::Calibration rig = paperLikeCalibration();
    rig.cameraDistortion << -0.12, 0.08, 0, 0, 0;
    return rig;
}

Eigen::Isometry3d tiltedBoard(double axisDeg, double tiltDeg, double liftMm) {
    const Eigen::Vector3d middle(160, 230, 0);
    const Eigen::Vector3d axis(std::cos(axisDeg * M_PI / 180), std::sin(axisDeg * M_PI / 180), 0);
    return Eigen::Translation3d(middle + Eigen::Vector3d(0, 0, liftMm)) *
           Eigen::AngleAxisd(tiltDeg * M_PI / 180, axis) * Eigen::Translation3d(-middle);
}

std::vector<Eigen::Isometry3d> calibrationPoses() {
    return {Eigen::Isometry3d::Identity(), tiltedBoard(0, 25, 40),   tiltedBoard(0, -12, 50),
            tiltedBoard(90, 25, 40),       tiltedBoard(90, -25, 60), tiltedBoard(45, 20, 80)};
}

}  // namespace everytouch::test
