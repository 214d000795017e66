#include "core/calibration_correction.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string_view>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "core/camera_model.h"
#include "core/camera_relocation.h"
#include "core/geometry.h"

namespace everytouch::core {

namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix26d = Eigen::Matrix<double, 2, 6>;

// Steps of the numerical derivatives by the camera's pose and the table's plane: a microradian turns the
// table's points by a few thousandths of a camera pixel, a micrometre moves them by less; both far above
// rounding, far below the curvature of the projection.
constexpr double kTurnStepRad = 1e-6;
constexpr double kShiftStepMm = 1e-3;
// Step of the camera-to-projector map's derivative, camera pixels: the map is smooth over a pixel.
constexpr double kPixelStep = 0.5;
// Gauss-Newton steps that refine the table's plane from the first one's linear fit: a tilt of several
// degrees moves the code nearly linearly, and each step takes what is left to a small fraction.
constexpr int kTableSteps = 4;
// Step of the derivative by the projector image's shift, projector pixels: the shift moves every panel pixel
// by itself, so the map is linear in it.
constexpr double kImageStepPx = 0.1;
// A tile is set aside when the move leaves it this many times the median tile's residual, in at most this
// many passes: a Gaussian residual's median is 1.18 sigma in two dimensions, so 3.5 medians is 4 sigma.
constexpr double kOutlierMedians = 3.5;
constexpr int kOutlierPasses = 2;

// The camera pose moved by `move`: a turn (rotation vector, radians) before the pose's own rotation, then a
// shift (mm) of the translation.
Eigen::Isometry3d movedPose(const Eigen::Isometry3d& pose, const Vector6d& move) {
    Eigen::Isometry3d moved = pose;
    const Eigen::Vector3d turn = move.head<3>();
    if (const double angle = turn.norm(); angle > 0.0)
        moved.linear() = Eigen::AngleAxisd(angle, turn / angle).toRotationMatrix() * pose.linear();
    moved.translation() = pose.translation() + move.tail<3>();
    return moved;
}

Eigen::Vector2d seenAt(const CameraModel& camera, const Eigen::Isometry3d& pose,
                       const Eigen::Vector3d& point) {
    return camera.project(pose * point);
}

// The table's plane moved by `move` under the rig: turned by move[0] and move[1] radians about the table's x
// and y axes through `centre` (table mm), then lifted by move[2] mm. A point of the moved table at X lies at
// the returned transform times X in the table's frame from before.
Eigen::Isometry3d movedTable(const Eigen::Vector3d& move, const Eigen::Vector3d& centre) {
    Eigen::Isometry3d moved = Eigen::Isometry3d::Identity();
    const Eigen::Vector3d turn(move.x(), move.y(), 0.0);
    if (const double angle = turn.norm(); angle > 0.0)
        moved.linear() = Eigen::AngleAxisd(angle, turn / angle).toRotationMatrix();
    moved.translation() = centre - moved.linear() * centre + Eigen::Vector3d(0.0, 0.0, move.z());
    return moved;
}

// The rig against the table moved by `table` (movedTable): both devices keep their places, the table's frame
// moves.
Calibration withTableMoved(const Calibration& calibration, const Eigen::Isometry3d& table) {
    Calibration moved = calibration;
    moved.tableToCamera = calibration.tableToCamera * table;
    moved.tableToProjector = calibration.tableToProjector * table;
    return moved;
}

// Solves the least-squares normal equations of N parameters of different units: balanced by their diagonal,
// with the directions the tiles cannot tell apart dropped (a far camera's turn and shift nearly trade for
// each other).
template <int N>
Eigen::Matrix<double, N, 1> solveBalanced(const Eigen::Matrix<double, N, N>& normal,
                                          const Eigen::Matrix<double, N, 1>& right) {
    using Vector = Eigen::Matrix<double, N, 1>;
    const Vector scale = normal.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
    const Eigen::Matrix<double, N, N> balanced = scale.asDiagonal() * normal * scale.asDiagonal();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> solver(balanced);
    const Vector along = solver.eigenvectors().transpose() * (scale.asDiagonal() * right);
    const double largest = solver.eigenvalues().maxCoeff();
    Vector solved = Vector::Zero();
    for (int k = 0; k < N; ++k)
        if (solver.eigenvalues()[k] > 1e-9 * largest)
            solved[k] = along[k] / solver.eigenvalues()[k];
    return scale.asDiagonal() * (solver.eigenvectors() * solved);
}

// The projector's image shifted on its panel by `shiftPx`: its principal point moved.
Eigen::Matrix3d shiftedImage(const Eigen::Matrix3d& projectorMatrix, const Eigen::Vector2d& shiftPx) {
    Eigen::Matrix3d shifted = projectorMatrix;
    shifted(0, 2) += shiftPx.x();
    shifted(1, 2) += shiftPx.y();
    return shifted;
}

}  // namespace

std::optional<std::string> CorrectionOptions::validate() const {
    if (!(noiseMultiple >= 1.0 && noiseMultiple <= 100.0))
        return "noiseMultiple: must be in [1, 100]";
    if (!(leastErrorPx > 0.0 && leastErrorPx <= 10.0))
        return "leastErrorPx: must be in (0, 10] projector pixels";
    return std::nullopt;
}

CalibrationCorrector::CalibrationCorrector(const CorrectionOptions& options) : options_(options) {
    if (auto problem = options.validate())
        throw std::invalid_argument("calibration correction options: " + *problem);
}

void CalibrationCorrector::setRig(const Calibration& calibration, int tilesPerRound) {
    if (tilesPerRound < kMinRelocationTiles)
        throw std::invalid_argument("calibration correction: a round needs at least " +
                                    std::to_string(kMinRelocationTiles) + " tiles");
    calibration_ = calibration;
    const Eigen::Vector2d centre = calibration.displayCentreOnTable();
    tableCentre_ = Eigen::Vector3d(centre.x(), centre.y(), 0.0);
    tilesPerRound_ = tilesPerRound;
    terms_.reserve(static_cast<std::size_t>(tilesPerRound));
    residuals_.reserve(static_cast<std::size_t>(tilesPerRound));
    inliers_.reserve(static_cast<std::size_t>(tilesPerRound));
    judged_ = 0;
    heldNoisePx_.reset();
    roundsOff_ = 0;
    problem_.clear();
}

CalibrationCorrector::TileGeometry CalibrationCorrector::tileGeometry(
    const CameraModel& camera, const Eigen::Matrix3d& cameraToProjector,
    const Eigen::Matrix3d& projectorToTable, const TileShift& tile) {
    const auto lit = [&](const Eigen::Vector2d& raw) {
        return applyHomography(cameraToProjector, camera.undistortPixel(raw));
    };
    TileGeometry geometry;
    geometry.panelPixel = lit(tile.centre);
    const Eigen::Vector2d onTable = applyHomography(projectorToTable, geometry.panelPixel);
    geometry.tablePoint = Eigen::Vector3d(onTable.x(), onTable.y(), 0.0);
    geometry.observed = tile.centre + tile.cameraPx;
    const Eigen::Vector2d dx = Eigen::Vector2d(kPixelStep, 0.0), dy = Eigen::Vector2d(0.0, kPixelStep);
    geometry.toProjector.col(0) = (lit(tile.centre + dx) - lit(tile.centre - dx)) / (2.0 * kPixelStep);
    geometry.toProjector.col(1) = (lit(tile.centre + dy) - lit(tile.centre - dy)) / (2.0 * kPixelStep);
    return geometry;
}

void CalibrationCorrector::prepareTerms(const std::vector<TileShift>& tiles) {
    const Calibration& calibration = *calibration_;
    const CameraModel camera{calibration.cameraMatrix, calibration.cameraDistortion};
    const Eigen::Matrix3d cameraToProjector = calibration.cameraToProjectorHomography();
    const Eigen::Matrix3d projectorToTable = calibration.tableToProjectorHomography().inverse();
    const Eigen::Isometry3d& pose = calibration.tableToCamera;
    // Where the table points of panel pixels lie once the image shifted by a step along x or y.
    Eigen::Matrix3d imageSteppedToTable[2];
    for (int k = 0; k < 2; ++k)
        imageSteppedToTable[k] = planeToImageHomography(shiftedImage(calibration.projectorMatrix,
                                                                     kImageStepPx * Eigen::Vector2d::Unit(k)),
                                                        calibration.tableToProjector, 0.0)
                                     .inverse();
    terms_.clear();
    for (const TileShift& tile : tiles) {
        const TileGeometry geometry = tileGeometry(camera, cameraToProjector, projectorToTable, tile);
        const Eigen::Vector2d predicted = seenAt(camera, pose, geometry.tablePoint);
        Matrix26d derivative;
        for (int k = 0; k < 6; ++k) {
            Vector6d move = Vector6d::Zero();
            move[k] = k < 3 ? kTurnStepRad : kShiftStepMm;
            derivative.col(k) =
                (seenAt(camera, movedPose(pose, move), geometry.tablePoint) - predicted) / move[k];
        }
        Eigen::Matrix2d imageDerivative;
        for (int k = 0; k < 2; ++k) {
            const Eigen::Vector2d stepped = applyHomography(imageSteppedToTable[k], geometry.panelPixel);
            imageDerivative.col(k) =
                (seenAt(camera, pose, Eigen::Vector3d(stepped.x(), stepped.y(), 0.0)) - predicted) /
                kImageStepPx;
        }
        Eigen::Matrix<double, 2, 3> tableDerivative;
        for (int k = 0; k < 3; ++k) {
            Eigen::Vector3d move = Eigen::Vector3d::Zero();
            move[k] = k < 2 ? kTurnStepRad : kShiftStepMm;
            tableDerivative.col(k) = (seenThrough(withTableMoved(calibration, movedTable(move, tableCentre_)),
                                                  camera, geometry.panelPixel) -
                                      predicted) /
                                     move[k];
        }
        terms_.push_back({geometry, geometry.toProjector * derivative, geometry.toProjector * imageDerivative,
                          geometry.toProjector * tableDerivative,
                          geometry.toProjector * (geometry.observed - predicted), true, 0.0});
    }
}

CalibrationCorrector::Fit CalibrationCorrector::fitMove() {
    Eigen::Matrix<double, 6, 6> normal = Eigen::Matrix<double, 6, 6>::Zero();
    Vector6d right = Vector6d::Zero();
    double squares = 0.0;
    int used = 0;
    for (const TileTerm& term : terms_) {
        if (!term.inlier)
            continue;
        normal += term.onPanel.transpose() * term.onPanel;
        right += term.onPanel.transpose() * term.shift;
        squares += term.shift.squaredNorm();
        ++used;
    }
    const Vector6d move = solveBalanced<6>(normal, right);
    double left = 0.0;
    for (TileTerm& term : terms_) {
        term.residualPx = (term.shift - term.onPanel * move).norm();
        if (term.inlier)
            left += term.residualPx * term.residualPx;
    }
    return summarise(squares, left, used, 6);
}

CalibrationCorrector::Fit CalibrationCorrector::summarise(double squares, double left, int tiles,
                                                          int parameters) {
    const double n = static_cast<double>(tiles);
    Fit fit;
    fit.beforePx = std::sqrt(squares / n);
    fit.explainedPx = std::sqrt(std::max(0.0, squares - left) / n);
    fit.leftPx = std::sqrt(left / n);
    // Two equations a tile.
    fit.noisePx = std::sqrt(left / (n - 0.5 * parameters));
    return fit;
}

template <int N>
CalibrationCorrector::Fit CalibrationCorrector::fitLinear(Eigen::Matrix<double, 2, N> TileTerm::*onPanel,
                                                          Eigen::Matrix<double, N, 1>& parameters) const {
    Eigen::Matrix<double, N, N> normal = Eigen::Matrix<double, N, N>::Zero();
    Eigen::Matrix<double, N, 1> right = Eigen::Matrix<double, N, 1>::Zero();
    double squares = 0.0;
    int used = 0;
    for (const TileTerm& term : terms_) {
        if (!term.inlier)
            continue;
        normal += (term.*onPanel).transpose() * (term.*onPanel);
        right += (term.*onPanel).transpose() * term.shift;
        squares += term.shift.squaredNorm();
        ++used;
    }
    parameters = solveBalanced<N>(normal, right);
    double left = 0.0;
    for (const TileTerm& term : terms_)
        if (term.inlier)
            left += (term.shift - term.*onPanel * parameters).squaredNorm();
    return summarise(squares, left, used, N);
}

Eigen::Vector2d CalibrationCorrector::seenThrough(const Calibration& calibration, const CameraModel& camera,
                                                  const Eigen::Vector2d& panelPixel) {
    const Eigen::Vector2d lit =
        applyHomography(calibration.tableToProjectorHomography().inverse(), panelPixel);
    return seenAt(camera, calibration.tableToCamera, Eigen::Vector3d(lit.x(), lit.y(), 0.0));
}

Calibration CalibrationCorrector::refinedTable(Eigen::Vector3d move) const {
    const Calibration& calibration = *calibration_;
    const CameraModel camera{calibration.cameraMatrix, calibration.cameraDistortion};
    // Gauss-Newton with the derivatives at the calibration: each step fits what the plane moved so far
    // leaves.
    for (int step = 1; step < kTableSteps; ++step) {
        const Calibration moved = withTableMoved(calibration, movedTable(move, tableCentre_));
        Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
        Eigen::Vector3d right = Eigen::Vector3d::Zero();
        for (const TileTerm& term : terms_) {
            if (!term.inlier)
                continue;
            const Eigen::Vector2d left =
                term.geometry.toProjector *
                (term.geometry.observed - seenThrough(moved, camera, term.geometry.panelPixel));
            normal += term.tableOnPanel.transpose() * term.tableOnPanel;
            right += term.tableOnPanel.transpose() * left;
        }
        move += solveBalanced<3>(normal, right);
    }
    return withTableMoved(calibration, movedTable(move, tableCentre_));
}

CalibrationCorrector::Fit CalibrationCorrector::fitMoveRobustly(const std::vector<TileShift>& tiles) {
    prepareTerms(tiles);
    Fit fit = fitMove();
    // A tile whose peak was one of chance, or that was read while the camera moved, is far off any move
    // that fits the others: such tiles are set aside while enough remain for the camera's pose.
    for (int pass = 0; pass < kOutlierPasses; ++pass) {
        residuals_.clear();
        for (const TileTerm& term : terms_)
            if (term.inlier)
                residuals_.push_back(term.residualPx);
        const auto middle = residuals_.begin() + static_cast<std::ptrdiff_t>(residuals_.size() / 2);
        std::nth_element(residuals_.begin(), middle, residuals_.end());
        const double limit = std::max(kOutlierMedians * *middle, 0.5 * options_.leastErrorPx);
        int kept = 0, dropped = 0;
        for (const TileTerm& term : terms_)
            if (term.inlier)
                (term.residualPx > limit ? dropped : kept) += 1;
        if (dropped == 0 || kept < kMinRelocationTiles)
            break;
        for (TileTerm& term : terms_)
            term.inlier = term.inlier && term.residualPx <= limit;
        fit = fitMove();
    }
    return fit;
}

double CalibrationCorrector::inlierMisregistrationPx(const Calibration& corrected) const {
    const CameraModel camera{corrected.cameraMatrix, corrected.cameraDistortion};
    double squares = 0.0;
    int used = 0;
    for (const TileTerm& term : terms_) {
        if (!term.inlier)
            continue;
        const Eigen::Vector2d predicted = seenThrough(corrected, camera, term.geometry.panelPixel);
        squares += (term.geometry.toProjector * (term.geometry.observed - predicted)).squaredNorm();
        ++used;
    }
    return std::sqrt(squares / static_cast<double>(used));
}

std::optional<CalibrationCorrection> CalibrationCorrector::update(std::uint64_t measured,
                                                                  const std::vector<TileShift>& latest) {
    if (measured < judged_)
        judged_ = 0;  // the check started over
    if (!calibration_ || measured < judged_ + static_cast<std::uint64_t>(tilesPerRound_) ||
        static_cast<int>(latest.size()) < tilesPerRound_)
        return std::nullopt;
    judged_ = measured;
    problem_.clear();
    // A round that straddles a knock shows two misregistrations at once: a problem is told once two rounds
    // running show it.
    const auto off = [&](std::string_view why) -> std::optional<CalibrationCorrection> {
        if (++roundsOff_ >= 2)
            problem_ = why;
        return std::nullopt;
    };
    const Fit move = fitMoveRobustly(latest);
    Eigen::Vector2d imageShiftPx;
    const Fit image = fitLinear(&TileTerm::imageOnPanel, imageShiftPx);
    Eigen::Vector3d tableMove;
    const Fit table = fitLinear(&TileTerm::tableOnPanel, tableMove);
    // What would count as the calibration holding (below) is what a correction may leave.
    const double allowedPx =
        std::max(options_.leastErrorPx, options_.noiseMultiple * heldNoisePx_.value_or(0.0));
    // The simplest explanation that suffices: a creep corrected as many small moves of the camera adds up to
    // a pose that no longer fits, while a knock leaves far more than allowedPx after any shift of the image.
    // Then the table's plane (three parameters), before the camera's six: a tilted table corrected as a move
    // of the camera leaves the code registered on the plane but the camera where it is not, and beyond a
    // few degrees not even that.
    const bool imageCrept = image.leftPx <= allowedPx;
    const bool tableMoved = !imageCrept && table.leftPx <= allowedPx;
    const Fit& fit = imageCrept ? image : tableMoved ? table : move;
    const double notableNoisePx = options_.noiseMultiple * fit.noisePx;
    if (fit.beforePx < allowedPx) {
        // The calibration holds: what the tiles show is their noise.
        heldNoisePx_ = move.noisePx;
        roundsOff_ = 0;
        return std::nullopt;
    }
    char figures[256];
    if (fit.explainedPx < std::max(options_.leastErrorPx, notableNoisePx)) {
        // What neither explains is within what the calibration may be off by: the calibration is a little
        // off, by no more than the tiles' noise shows clearly (a projector's image creeping by 2 px a minute,
        // seen a few seconds in). It is watched, and corrected once the explanation stands out.
        if (fit.noisePx < options_.leastErrorPx) {
            roundsOff_ = 0;
            return std::nullopt;
        }
        std::snprintf(
            figures, sizeof figures,
            "the code lies %.2f projector px from where the calibration puts it, and no move of the "
            "camera or of the table or shift of the projector's image explains it: the one that fits best "
            "leaves %.2f px",
            fit.beforePx, fit.noisePx);
        return off(figures);
    }
    inliers_.clear();
    for (std::size_t i = 0; i < latest.size(); ++i)
        if (terms_[i].inlier)
            inliers_.push_back(latest[i]);
    CalibrationCorrection correction;
    correction.calibration = *calibration_;
    if (imageCrept) {
        correction.calibration.projectorMatrix = shiftedImage(calibration_->projectorMatrix, imageShiftPx);
        correction.what = "projector";
    } else if (tableMoved) {
        correction.calibration = refinedTable(tableMove);
        correction.what = "table";
    } else {
        Result<CameraRelocation> relocation = relocateCamera(*calibration_, inliers_);
        if (!relocation.ok())
            return off(relocation.failure().message);
        correction.calibration.tableToCamera = relocation->tableToCamera;
        correction.what = "camera";
    }
    correction.beforePx = fit.beforePx;
    correction.afterPx = inlierMisregistrationPx(correction.calibration);
    correction.tiles = static_cast<int>(inliers_.size());
    const double noisePx = heldNoisePx_.value_or(fit.noisePx);
    // What would count as holding is good enough, even beside a very quiet camera's noise.
    if (correction.afterPx > std::max(options_.leastErrorPx, options_.noiseMultiple * noisePx)) {
        std::snprintf(figures, sizeof figures,
                      "the code lies %.2f projector px from where the calibration puts it, and the corrected "
                      "%s would leave %.2f px, more than the %.2f px of noise seen",
                      correction.beforePx, correction.what.c_str(), correction.afterPx, noisePx);
        return off(figures);
    }
    calibration_ = correction.calibration;
    roundsOff_ = 0;
    judged_ = 0;  // the check measures against the corrected calibration from its first tile on
    return correction;
}

}  // namespace everytouch::core
