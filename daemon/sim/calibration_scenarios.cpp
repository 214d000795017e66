#include "sim/calibration_scenarios.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

#include <opencv2/core.hpp>

#include "sim/easing.h"

namespace everytouch::sim {

namespace {

Eigen::Isometry3d blend(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to, double s) {
    const Eigen::Quaterniond a(from.rotation()), b(to.rotation());
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = a.slerp(s, b).toRotationMatrix();
    pose.translation() = from.translation() + (to.translation() - from.translation()) * s;
    return pose;
}

constexpr double kSearchStepMm = 8.0;     // coarse grid of card places, refined to 0.5 mm
constexpr double kSearchReachMm = 230.0;  // from the panel centre's ray, along the surface
constexpr double kBoardMarginMm = 8.0;    // board edge beyond the chessboard and the card: fingers hold it
constexpr double kMaxViewDeg = 50.0;      // the steepest view of the card the scenarios allow
constexpr double kYawJitterDeg = 3.0;     // a card laid by hand is not square to the table

}  // namespace

CardPlacement placeCard(const CalibrationStage& stage, const Eigen::Isometry3d& surfaceToTable,
                        const std::optional<cv::Size2d>& boardSize, double yawJitterDeg) {
    std::array<Eigen::Vector2d, 4> chessboard;
    const std::array<Eigen::Vector3d, 4> onSurface = stage.chessboardOn(surfaceToTable);
    const Eigen::Isometry3d tableToSurface = surfaceToTable.inverse();
    for (int i = 0; i < 4; ++i)
        chessboard[i] = (tableToSurface * onSurface[i]).head<2>();
    CardPlacement best;
    const auto consider = [&](const Eigen::Vector2d& centre, double yawDeg) {
        const Eigen::Rotation2Dd turn(yawDeg * M_PI / 180.0);
        const Eigen::Vector2d corner = centre - turn * Eigen::Vector2d(kCardLengthMm / 2, kCardWidthMm / 2);
        CardPlacement candidate;
        candidate.card = cardOn(surfaceToTable, corner, yawDeg);
        const CardClearance clearance = stage.clearance(candidate.card);
        candidate.clearancePx = clearance.least();
        if (candidate.clearancePx <= best.clearancePx || clearance.cameraViewDeg > kMaxViewDeg)
            return;
        if (boardSize) {
            Eigen::Vector2d low = chessboard[0], high = chessboard[0];
            for (const Eigen::Vector2d& point : chessboard)
                low = low.cwiseMin(point), high = high.cwiseMax(point);
            for (const Eigen::Vector3d& point : cardCorners(candidate.card)) {
                const Eigen::Vector2d local = (tableToSurface * point).head<2>();
                low = low.cwiseMin(local), high = high.cwiseMax(local);
            }
            // The board's centre may be anywhere that keeps both within its margins; it goes uphill as far
            // as that allows, so that its lower edge clears the table.
            const Eigen::Vector2d half(boardSize->width / 2.0 - kBoardMarginMm,
                                       boardSize->height / 2.0 - kBoardMarginMm);
            const Eigen::Vector2d lowest = high - half, highest = low + half;
            if (lowest.x() > highest.x() || lowest.y() > highest.y())
                return;
            const Eigen::Vector2d uphill = surfaceToTable.linear().row(2).head<2>().transpose();
            const Eigen::Vector2d middle(uphill.x() > 0 ? highest.x() : lowest.x(),
                                         uphill.y() > 0 ? highest.y() : lowest.y());
            BoardProp board;
            board.sizeMm = *boardSize;
            board.faceToTable = surfaceToTable * Eigen::Translation3d(middle.x(), middle.y(), 0.0);
            for (const Eigen::Vector3d& point : boardCorners(board))
                if (point.z() < 0.0)
                    return;
            candidate.board = board;
        }
        best = candidate;
    };
    for (double yaw : {0.0, 90.0})
        for (double y = -kSearchReachMm; y <= kSearchReachMm; y += kSearchStepMm)
            for (double x = -kSearchReachMm; x <= kSearchReachMm; x += kSearchStepMm)
                consider({x, y}, yaw + yawJitterDeg);
    // Refine around the best place found.
    if (best.clearancePx > -std::numeric_limits<double>::infinity()) {
        const Eigen::Isometry3d cardOnSurface = tableToSurface * best.card.faceToTable;
        const Eigen::Vector2d corner = cardOnSurface.translation().head<2>();
        const Eigen::Matrix2d r = cardOnSurface.linear().topLeftCorner<2, 2>();
        const double yaw = std::atan2(r(1, 0), r(0, 0)) * 180.0 / M_PI;
        const Eigen::Vector2d centre = corner + Eigen::Rotation2Dd(yaw * M_PI / 180.0) *
                                                    Eigen::Vector2d(kCardLengthMm / 2, kCardWidthMm / 2);
        for (double dy = -kSearchStepMm; dy <= kSearchStepMm; dy += 0.5)
            for (double dx = -kSearchStepMm; dx <= kSearchStepMm; dx += 0.5)
                consider(centre + Eigen::Vector2d(dx, dy), yaw);
    }
    return best;
}

namespace {

// A placement the card fits in, or std::invalid_argument naming what leaves it no room.
const CardPlacement& requireRoom(const CardPlacement& placement, const std::string& where, bool board) {
    if ((board && !placement.board) || !(placement.clearancePx > 0.0)) {
        char message[256];
        std::snprintf(
            message, sizeof message,
            "%s: on this rig the card does not fit between the projected chessboard and the edges of "
            "the projector's light and the camera's view%s (room: %.1f px)",
            where.c_str(), board ? " on a board of 420 x 297 mm" : "",
            std::max(placement.clearancePx, -999.0));
        throw std::invalid_argument(message);
    }
    return placement;
}

cv::RNG scenarioRng(std::uint64_t seed, int id) {
    std::uint64_t state =
        seed * 0x9E3779B97F4A7C15ull + static_cast<std::uint64_t>(id) * 0xBF58476D1CE4E5B9ull;
    state ^= state >> 31;
    return cv::RNG(state | 1);
}

}  // namespace

core::ChessboardOptions calibrationChessboard() {
    core::ChessboardOptions options;
    options.squarePx = 40;
    return options;
}

double CardClearance::least() const {
    return std::min({chessboardPx, lightPx, cameraPx});
}

CalibrationStage::CalibrationStage(const core::Calibration& calibration,
                                   const core::ChessboardOptions& chessboard)
    : calibration_(calibration) {
    const std::vector<Eigen::Vector2d> corners =
        core::projectorChessboardCorners(chessboard, calibration.projectorSize);
    Eigen::Vector2d low = corners.front(), high = corners.front();
    for (const Eigen::Vector2d& corner : corners)
        low = low.cwiseMin(corner), high = high.cwiseMax(corner);
    chessboardEdges_ << low.x() - chessboard.squarePx, low.y() - chessboard.squarePx,
        high.x() + chessboard.squarePx, high.y() + chessboard.squarePx;
}

Eigen::Vector2d CalibrationStage::toProjector(const Eigen::Vector3d& point) const {
    const Eigen::Vector3d q = calibration_.projectorMatrix * (calibration_.tableToProjector * point);
    return q.head<2>() / q.z();
}

Eigen::Vector2d CalibrationStage::toCamera(const Eigen::Vector3d& point) const {
    const Eigen::Vector3d q = calibration_.cameraMatrix * (calibration_.tableToCamera * point);
    return q.head<2>() / q.z();
}

std::array<Eigen::Vector3d, 4> CalibrationStage::chessboardOn(const Eigen::Isometry3d& surfaceToTable) const {
    const Eigen::Isometry3d projectorToTable = calibration_.tableToProjector.inverse();
    const Eigen::Vector3d centre = projectorToTable.translation();
    const Eigen::Vector3d normal = surfaceToTable.linear().col(2);
    const Eigen::Vector3d origin = surfaceToTable.translation();
    std::array<Eigen::Vector3d, 4> corners;
    const Eigen::Vector4d& e = chessboardEdges_;
    const Eigen::Vector2d panel[4] = {{e[0], e[1]}, {e[2], e[1]}, {e[2], e[3]}, {e[0], e[3]}};
    for (int i = 0; i < 4; ++i) {
        const Eigen::Vector3d direction =
            projectorToTable.linear() * (calibration_.projectorMatrix.inverse() * panel[i].homogeneous());
        corners[i] = centre + direction * (normal.dot(origin - centre) / normal.dot(direction));
    }
    return corners;
}

Eigen::Vector3d CalibrationStage::panelCentreAt(double heightMm) const {
    const Eigen::Isometry3d projectorToTable = calibration_.tableToProjector.inverse();
    const Eigen::Vector3d centre = projectorToTable.translation();
    const Eigen::Vector2d panel((calibration_.projectorSize.width - 1) / 2.0,
                                (calibration_.projectorSize.height - 1) / 2.0);
    const Eigen::Vector3d direction =
        projectorToTable.linear() * (calibration_.projectorMatrix.inverse() * panel.homogeneous());
    return centre + direction * ((heightMm - centre.z()) / direction.z());
}

CardClearance CalibrationStage::clearance(const CardProp& card) const {
    CardClearance result;
    const Eigen::Vector4d& e = chessboardEdges_;
    const double panelW = calibration_.projectorSize.width - 0.5,
                 panelH = calibration_.projectorSize.height - 0.5;
    const double cameraW = calibration_.cameraSize.width - 0.5,
                 cameraH = calibration_.cameraSize.height - 0.5;
    Eigen::Vector2d low(1e18, 1e18), high(-1e18, -1e18);
    result.lightPx = result.cameraPx = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3d& corner : cardCorners(card)) {
        const Eigen::Vector2d p = toProjector(corner), c = toCamera(corner);
        low = low.cwiseMin(p), high = high.cwiseMax(p);
        result.lightPx = std::min({result.lightPx, p.x() + 0.5, panelW - p.x(), p.y() + 0.5, panelH - p.y()});
        result.cameraPx =
            std::min({result.cameraPx, c.x() + 0.5, cameraW - c.x(), c.y() + 0.5, cameraH - c.y()});
    }
    const Eigen::Vector3d centre = card.faceToTable * Eigen::Vector3d(kCardLengthMm / 2, kCardWidthMm / 2, 0);
    const Eigen::Vector3d toCamera = calibration_.tableToCamera.inverse().translation() - centre;
    result.cameraViewDeg =
        std::acos(std::clamp(card.faceToTable.linear().col(2).dot(toCamera.normalized()), -1.0, 1.0)) *
        180.0 / M_PI;
    result.chessboardPx = std::max({e[0] - high.x(), low.x() - e[2], e[1] - high.y(), low.y() - e[3]});
    return result;
}

TableSetupScenario::TableSetupScenario(const ScenarioContext& context) {
    const CalibrationStage stage(context.calibration, calibrationChessboard());
    cv::RNG rng = scenarioRng(context.seed, 20);
    const Eigen::Isometry3d table(Eigen::Translation3d(stage.panelCentreAt(0.0)));
    card_ = requireRoom(placeCard(stage, table, std::nullopt, rng.uniform(-kYawJitterDeg, kYawJitterDeg)),
                        "table-setup", false)
                .card;
}

std::vector<Props> TableSetupScenario::stillProps() const {
    return {at(0.0).props};
}

std::vector<Props> PairCalibrationScenario::stillProps() const {
    std::vector<Props> all;
    for (const Pose& pose : poses_)
        all.push_back({pose.card, pose.board});
    return all;
}

SceneState TableSetupScenario::at(double) const {
    SceneState state;
    state.content = ContentKind::White;
    state.props.card = card_;
    return state;
}

PairCalibrationScenario::PairCalibrationScenario(const ScenarioContext& context) {
    const CalibrationStage stage(context.calibration, calibrationChessboard());
    cv::RNG rng = scenarioRng(context.seed, 21);
    Pose table;
    table.card =
        requireRoom(placeCard(stage, Eigen::Isometry3d(Eigen::Translation3d(stage.panelCentreAt(0.0))),
                              std::nullopt, rng.uniform(-kYawJitterDeg, kYawJitterDeg)),
                    "pair-calibration, the card on the table", false)
            .card;
    poses_.push_back(table);
    // Five tilts about different axes, each at the lift in 40-80 mm (where the panel's centre ray meets the
    // board) that leaves the card the most room. The dialogue takes a pose only when the card's surface is
    // tilted by 10 degrees or more against every pose before (service::PoseCaptureOptions::minTiltDeg),
    // measured from the card's stripe: on this rig within 2.5 degrees of the truth with the camera's true
    // matrix, and up to 3.3 degrees short with the matrix it guesses before any calibration (focal length
    // the image width, 20 % short). So the surfaces differ by at least kMinTiltDifferenceDeg from each other
    // and from the table's. The nominal tilts are the five that keep the surfaces farthest apart on the
    // default rig (about 17 degrees) while leaving the card 5 px or more and a view of it within 48 degrees:
    // all face the rig, as its camera looks at the far side of the table at about 45 degrees and sees a card
    // on a surface tilted away from it too obliquely. Where a rig leaves the card less than kComfortPx at a
    // nominal tilt, the tilt moves to where it has the most room (axis +-10 degrees, tilt +-5 within 12-30)
    // while still differing by kMinTiltDifferenceDeg from the surfaces before it.
    struct Tilt {
        double axisDeg, tiltDeg;
    };
    constexpr Tilt kTilts[5] = {{270.0, 26.0}, {315.0, 18.0}, {345.0, 29.5}, {30.0, 18.0}, {75.0, 26.0}};
    constexpr double kComfortPx = 2.0;
    std::vector<Eigen::Vector3d> normals{Eigen::Vector3d::UnitZ()};
    for (const Tilt& tilt : kTilts) {
        const double axisJitter = rng.uniform(-2.0, 2.0), tiltJitter = rng.uniform(-0.5, 0.5);
        const double yawJitter = rng.uniform(-kYawJitterDeg, kYawJitterDeg);
        Pose pose;
        CardPlacement best;
        const auto tryTilt = [&](double axisDeg, double tiltDeg) {
            const Eigen::Vector3d axis(std::cos(axisDeg * M_PI / 180.0), std::sin(axisDeg * M_PI / 180.0), 0);
            const Eigen::Vector3d normal =
                Eigen::AngleAxisd(tiltDeg * M_PI / 180.0, axis) * Eigen::Vector3d::UnitZ();
            for (const Eigen::Vector3d& other : normals)
                if (std::acos(std::min(1.0, normal.dot(other))) * 180.0 / M_PI < kMinTiltDifferenceDeg)
                    return;
            for (double lift = 40.0; lift <= 80.0; lift += 10.0) {
                const Eigen::Isometry3d surface = Eigen::Translation3d(stage.panelCentreAt(lift)) *
                                                  Eigen::AngleAxisd(tiltDeg * M_PI / 180.0, axis);
                CardPlacement placement = placeCard(stage, surface, BoardProp().sizeMm, yawJitter);
                if (placement.board && placement.clearancePx > best.clearancePx) {
                    best = placement;
                    pose.axisDeg = axisDeg, pose.tiltDeg = tiltDeg, pose.liftMm = lift;
                }
            }
        };
        tryTilt(tilt.axisDeg + axisJitter, tilt.tiltDeg + tiltJitter);
        if (!(best.clearancePx >= kComfortPx))
            for (double axisStep : {-10.0, 0.0, 10.0})
                for (double tiltStep : {-5.0, 0.0, 5.0})
                    tryTilt(tilt.axisDeg + axisJitter + axisStep,
                            std::clamp(tilt.tiltDeg + tiltJitter + tiltStep, 12.0, 30.0));
        char where[96];
        std::snprintf(where, sizeof where,
                      "pair-calibration, the board tilted %.0f degrees about %.0f degrees", tilt.tiltDeg,
                      tilt.axisDeg);
        requireRoom(best, where, true);
        pose.board = best.board;
        pose.card = best.card;
        poses_.push_back(pose);
        normals.push_back(pose.board->faceToTable.linear().col(2));
    }
}

double PairCalibrationScenario::holdStart(int pose) const {
    return pose * (kHoldSeconds + kMoveSeconds);
}

double PairCalibrationScenario::tableAgainAt() const {
    return holdEnd(static_cast<int>(poses_.size()) - 1) + kMoveSeconds;
}

double PairCalibrationScenario::cycleSeconds() const {
    return tableAgainAt();
}

SceneState PairCalibrationScenario::at(double seconds) const {
    const double local = std::max(seconds, 0.0);
    SceneState state;
    state.content = ContentKind::White;
    const int last = static_cast<int>(poses_.size()) - 1;
    if (local >= tableAgainAt()) {
        state.props.card = poses_.front().card;
        return state;
    }
    if (local >= holdEnd(last)) {
        // The board goes back towards the user and the card onto the table where it lay for the first pose.
        const double s = smootherStep((local - holdEnd(last)) / kMoveSeconds);
        const Pose& from = poses_[last];
        BoardProp board = *from.board;
        board.faceToTable = blend(from.board->faceToTable,
                                  Eigen::Translation3d(0.0, 350.0, 120.0) * from.board->faceToTable, s);
        state.props.board = board;
        state.props.card = CardProp{blend(from.card.faceToTable, poses_.front().card.faceToTable, s)};
        return state;
    }
    int k = 0;
    while (k < last && local >= holdEnd(k))
        ++k;
    const Pose& pose = poses_[k];
    if (local >= holdStart(k) || k == 0) {
        state.props.card = pose.card;
        state.props.board = pose.board;
        return state;
    }
    // Moving from pose k - 1 to pose k: the board comes in from the user's side for the first tilt.
    const Pose& from = poses_[k - 1];
    const double s = smootherStep((local - holdEnd(k - 1)) / kMoveSeconds);
    BoardProp board = *pose.board;
    const Eigen::Isometry3d start = from.board
                                        ? from.board->faceToTable
                                        : Eigen::Translation3d(0.0, 350.0, 120.0) * pose.board->faceToTable;
    board.faceToTable = blend(start, pose.board->faceToTable, s);
    // The card keeps its place on the board as it goes, moving over to where it lies in the new pose.
    const Eigen::Isometry3d fromOnBoard = start.inverse() * from.card.faceToTable;
    const Eigen::Isometry3d toOnBoard = pose.board->faceToTable.inverse() * pose.card.faceToTable;
    state.props.board = board;
    state.props.card = CardProp{board.faceToTable * blend(fromOnBoard, toOnBoard, s)};
    return state;
}

}  // namespace everytouch::sim
