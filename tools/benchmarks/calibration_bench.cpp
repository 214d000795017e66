// Costs of the calibration estimators on one core, on frames and correspondences of a paper-like rig (camera
// 648x488, projector 640x480, about 500 mm above the table, 4 cm apart).
#include <array>
#include <cmath>
#include <vector>

#include <benchmark/benchmark.h>
#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include "core/calibration.h"
#include "core/geometry.h"
#include "core/keystone.h"
#include "core/pair_calibration.h"
#include "core/projector_camera_pair.h"
#include "core/projector_chessboard.h"
#include "core/table_rectangle.h"
#include "core/table_setup.h"

namespace {

using namespace everytouch::core;

Eigen::Isometry3d lookAt(const Eigen::Vector3d& position, const Eigen::Vector3d& target) {
    const Eigen::Vector3d forward = (target - position).normalized();
    const Eigen::Vector3d right = -Eigen::Vector3d::UnitY().cross(forward).normalized();
    Eigen::Isometry3d deviceToTable = Eigen::Isometry3d::Identity();
    deviceToTable.linear() << right, forward.cross(right), forward;
    deviceToTable.translation() = position;
    return deviceToTable.inverse();
}

Calibration benchRig() {
    Calibration rig;
    rig.cameraSize = {648, 488};
    rig.cameraMatrix << 811, 0, 324, 0, 811, 244, 0, 0, 1;
    rig.cameraDistortion << -0.12, 0.08, 0, 0, 0;
    rig.projectorSize = {640, 480};
    rig.projectorMatrix << 1350, 0, 320, 0, 1350, 470, 0, 0, 1;
    rig.tableToCamera = lookAt({160, -120, 460}, {160, 120, 0});
    rig.tableToProjector = lookAt({200, -110, 470}, {160, 120, 0});
    return rig;
}

Calibration onBoard(const Calibration& rig, double axisDeg, double tiltDeg, double liftMm) {
    const Eigen::Vector3d middle(160, 230, 0);
    const Eigen::Vector3d axis(std::cos(axisDeg * M_PI / 180), std::sin(axisDeg * M_PI / 180), 0);
    const Eigen::Isometry3d boardToTable = Eigen::Translation3d(middle + Eigen::Vector3d(0, 0, liftMm)) *
                                           Eigen::AngleAxisd(tiltDeg * M_PI / 180, axis) *
                                           Eigen::Translation3d(-middle);
    Calibration moved = rig;
    moved.tableToCamera = rig.tableToCamera * boardToTable;
    moved.tableToProjector = rig.tableToProjector * boardToTable;
    return moved;
}

cv::Mat toMat(const Eigen::Matrix3d& matrix) {
    cv::Mat converted;
    cv::eigen2cv(matrix, converted);
    return converted;
}

// The camera frame of a projector image on the table, lens distortion left out (it does not change the
// costs).
cv::Mat cameraFrameOf(const Calibration& rig, const cv::Mat& projectorImage) {
    cv::Mat light;
    cv::warpPerspective(projectorImage, light, toMat(rig.projectorToCameraHomography()), rig.cameraSize,
                        cv::INTER_AREA);
    cv::Mat frame;
    light.convertTo(frame, CV_8UC1, 0.8, 20);
    return frame;
}

// The stripe lying on the lit table, under the projector's white.
cv::Mat stripeFrame(const Calibration& rig) {
    const cv::Mat white(rig.projectorSize, CV_8UC1, cv::Scalar(255));
    cv::Mat frame = cameraFrameOf(rig, white);
    std::vector<cv::Point> stripe;
    for (const Eigen::Vector2d& corner : {Eigen::Vector2d(120, 200), Eigen::Vector2d(205.5, 200),
                                          Eigen::Vector2d(205.5, 212.5), Eigen::Vector2d(120, 212.5)}) {
        const Eigen::Vector2d pixel = applyHomography(rig.tableToCameraHomography(), corner) * 16.0;
        stripe.emplace_back(static_cast<int>(pixel.x()), static_cast<int>(pixel.y()));
    }
    cv::fillConvexPoly(frame, stripe, cv::Scalar(8), cv::LINE_AA, 4);
    return frame;
}

PlaneView exactView(const Calibration& surface, int step) {
    const CameraModel camera{surface.cameraMatrix, surface.cameraDistortion};
    const auto seen = [&](const Eigen::Vector2d& mm) {
        return camera.project(surface.tableToCamera * Eigen::Vector3d(mm.x(), mm.y(), 0));
    };
    cv::RNG noise(7);
    PlaneView view;
    for (int x = 80; x <= 560; x += step) {
        for (int y = 60; y <= 420; y += step) {
            const Eigen::Vector2d projector(x, y);
            view.projectorPoints.push_back(projector);
            view.cameraPoints.push_back(
                seen(applyHomography(surface.tableToProjectorHomography().inverse(), projector)) +
                Eigen::Vector2d(noise.gaussian(0.05), noise.gaussian(0.05)));
        }
    }
    const Eigen::Vector2d stripe =
        applyHomography(surface.tableToProjectorHomography().inverse(), {320, 240}) -
        Eigen::Vector2d(42.75, 6.25);
    view.rectangleCorners = {seen(stripe), seen(stripe + Eigen::Vector2d(85.5, 0)),
                             seen(stripe + Eigen::Vector2d(85.5, 12.5)),
                             seen(stripe + Eigen::Vector2d(0, 12.5))};
    return view;
}

std::vector<PlaneView> calibrationViews(int step) {
    const Calibration rig = benchRig();
    return {exactView(rig, step),
            exactView(onBoard(rig, 0, 25, 40), step),
            exactView(onBoard(rig, 0, -12, 50), step),
            exactView(onBoard(rig, 90, 25, 40), step),
            exactView(onBoard(rig, 90, -25, 60), step),
            exactView(onBoard(rig, 45, 20, 80), step)};
}

void BM_ChessboardProjectorToCamera(benchmark::State& state) {
    cv::setNumThreads(1);
    const Calibration rig = benchRig();
    const ChessboardOptions options;
    cv::Mat board;
    renderProjectorChessboard(options, rig.projectorSize, board);
    const cv::Mat frame = cameraFrameOf(rig, board);
    const CameraModel camera{rig.cameraMatrix, rig.cameraDistortion};
    for (auto _ : state) {
        const Result<ProjectorToCameraEstimate> estimate =
            estimateProjectorToCamera(frame, options, rig.projectorSize, camera);
        if (!estimate.ok()) {
            state.SkipWithError(estimate.failure().message.c_str());
            break;
        }
        benchmark::DoNotOptimize(estimate->homography);
    }
}
BENCHMARK(BM_ChessboardProjectorToCamera)->Unit(benchmark::kMillisecond);

void BM_ChessboardAbsent(benchmark::State& state) {
    cv::setNumThreads(1);
    const Calibration rig = benchRig();
    const cv::Mat frame = stripeFrame(rig);
    for (auto _ : state)
        benchmark::DoNotOptimize(detectProjectedChessboard(frame, {}, rig.projectorSize).ok());
}
BENCHMARK(BM_ChessboardAbsent)->Unit(benchmark::kMillisecond);

void BM_StripeTableToCamera(benchmark::State& state) {
    cv::setNumThreads(1);
    const Calibration rig = benchRig();
    const cv::Mat frame = stripeFrame(rig);
    for (auto _ : state) {
        const Result<TableRectangleDetection> detection = findTableRectangle(frame, {});
        if (!detection.ok()) {
            state.SkipWithError(detection.failure().message.c_str());
            break;
        }
        benchmark::DoNotOptimize(detection->tableToCamera);
    }
}
BENCHMARK(BM_StripeTableToCamera)->Unit(benchmark::kMillisecond);

// Six poses; state.range(0) correspondences per view (54 as from the chessboard, 400 as thinned dense codes).
void BM_PairCalibration(benchmark::State& state) {
    cv::setNumThreads(1);
    const int step = state.range(0) <= 54 ? 60 : 22;
    const std::vector<PlaneView> views = calibrationViews(step);
    PairCalibrationOptions options;
    options.cameraSize = {648, 488};
    options.projectorSize = {640, 480};
    options.maxPointsPerView = static_cast<int>(state.range(0));
    for (auto _ : state) {
        const Result<PairCalibration> calibration = calibrateProjectorCameraPair(views, options);
        if (!calibration.ok()) {
            state.SkipWithError(calibration.failure().message.c_str());
            break;
        }
        benchmark::DoNotOptimize(calibration->pair.camera.matrix);
    }
    state.counters["points_per_view"] =
        static_cast<double>(std::min<size_t>(views[0].cameraPoints.size(), state.range(0)));
}
BENCHMARK(BM_PairCalibration)->Arg(54)->Arg(400)->Unit(benchmark::kMillisecond);

void BM_TableSetup(benchmark::State& state) {
    cv::setNumThreads(1);
    const Calibration rig = benchRig();
    const PlaneView table = exactView(rig, 60);
    const TableSetupOptions options;
    for (auto _ : state) {
        const Result<TableSetup> setup = setUpTable(pairOf(rig), table, options);
        if (!setup.ok()) {
            state.SkipWithError(setup.failure().message.c_str());
            break;
        }
        benchmark::DoNotOptimize(setup->calibration.tableToCamera);
    }
}
BENCHMARK(BM_TableSetup)->Unit(benchmark::kMillisecond);

void BM_Keystone(benchmark::State& state) {
    const Calibration rig = benchRig();
    for (auto _ : state)
        benchmark::DoNotOptimize(fitDisplayToTable(rig, {1280, 960})->displayToProjector);
}
BENCHMARK(BM_Keystone)->Unit(benchmark::kMicrosecond);

}  // namespace
