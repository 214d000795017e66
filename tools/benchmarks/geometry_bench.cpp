// Geometry costs paid per fingertip and per calibration change.
#include <benchmark/benchmark.h>

#include "core/calibration.h"
#include "core/geometry.h"

namespace {

everytouch::core::Calibration benchCalibration() {
    everytouch::core::Calibration calibration;
    calibration.cameraSize = {648, 488};
    calibration.cameraMatrix << 811, 0, 324, 0, 811, 244, 0, 0, 1;
    calibration.projectorSize = {640, 480};
    calibration.projectorMatrix << 1000, 0, 320, 0, 1000, 480, 0, 0, 1;
    calibration.tableToCamera =
        Eigen::Translation3d(-150, 100, 500) * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX());
    calibration.tableToProjector =
        Eigen::Translation3d(-160, 110, 480) * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX());
    calibration.displaySize = {1280, 960};
    calibration.displayToProjector = Eigen::Vector3d(0.5, 0.5, 1).asDiagonal();
    return calibration;
}

void BM_CameraToProjectorAtHeight(benchmark::State& state) {
    const everytouch::core::Calibration calibration = benchCalibration();
    double height = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(calibration.cameraToProjectorHomography(height));
        height += 0.001;
    }
}
BENCHMARK(BM_CameraToProjectorAtHeight);

}  // namespace
