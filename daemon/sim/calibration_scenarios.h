#pragma once

#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/calibration.h"
#include "core/projector_chessboard.h"
#include "sim/props.h"
#include "sim/scenario.h"

namespace everytouch::sim {

// The chessboard the daemon projects while it calibrates: 9 x 6 inner corners of 40 px squares, centred on
// the panel (service::tableSetUpChessboard()). The calibration scenarios keep their props clear of it.
core::ChessboardOptions calibrationChessboard();

// How well a card lies for the calibration, in pixels: how far its corners stay from the projected
// chessboard's squares, from the edges of the projector's light (panel pixels) and from the edges of the
// camera's view (camera pixels). The smallest of the three; negative when the card crosses one of them.
struct CardClearance {
    double chessboardPx = 0.0;
    double lightPx = 0.0;
    double cameraPx = 0.0;
    double least() const;
    // Angle between the card's normal and the camera's ray to its centre: the stripe looks that much
    // narrower; core::findTableRectangle accepts up to 55 degrees.
    double cameraViewDeg = 0.0;
};

// Where props lie relative to the projector's light, the projected chessboard and the camera's view.
class CalibrationStage {
public:
    CalibrationStage(const core::Calibration& calibration, const core::ChessboardOptions& chessboard);

    Eigen::Vector2d toProjector(const Eigen::Vector3d& point) const;
    Eigen::Vector2d toCamera(const Eigen::Vector3d& point) const;
    // The outer edges of the chessboard's squares on the panel: x0, y0, x1, y1, panel pixels.
    const Eigen::Vector4d& chessboardEdges() const { return chessboardEdges_; }
    // The chessboard's outer corners where they land on the plane z = 0 of `surfaceToTable`, table mm.
    std::array<Eigen::Vector3d, 4> chessboardOn(const Eigen::Isometry3d& surfaceToTable) const;
    // Where the ray of the panel's centre meets the plane z = heightMm, table mm.
    Eigen::Vector3d panelCentreAt(double heightMm) const;

    CardClearance clearance(const CardProp& card) const;

private:
    core::Calibration calibration_;
    Eigen::Vector4d chessboardEdges_;
};

// A still table with the card lying in the projected chessboard's border, where a user lays it for the quick
// set-up: fully lit, in the camera's view, clear of the chessboard. The place follows from the rig's
// geometry; the seed turns the card by a few degrees and picks among the places with the most room. A card's
// place on a surface, and the board around it when the surface is a board.
struct CardPlacement {
    CardProp card;
    std::optional<BoardProp> board;
    double clearancePx = -std::numeric_limits<double>::infinity();  // CardClearance::least()
};

// The card's place on the surface (z = 0 of `surfaceToTable`) with the most clearance, its long side along
// one of the surface's axes turned by `yawJitterDeg`, and seen at most 50 degrees off its normal. With
// `boardSize` the surface is a board of that size, placed to carry both the chessboard and the card (a margin
// from its edges to hold it by) without touching the table; no board fits when `board` is empty.
CardPlacement placeCard(const CalibrationStage& stage, const Eigen::Isometry3d& surfaceToTable,
                        const std::optional<cv::Size2d>& boardSize, double yawJitterDeg);

class TableSetupScenario final : public Scenario {
public:
    // Throws std::invalid_argument when the rig leaves the card no room.
    explicit TableSetupScenario(const ScenarioContext& context);
    SceneState at(double seconds) const override;
    double cycleSeconds() const override { return 10.0; }
    std::vector<Props> stillProps() const override;
    const CardProp& card() const { return card_; }

private:
    CardProp card_;
};

// The one-time pair calibration as a user performs it: the card on the bare table, then a white board held in
// five tilts, the card lying on it beside the projected chessboard, each pose held still and the board moved
// between them; then the board is taken away and the card laid on the table again, as the table set-up that
// follows asks ("calibrate full"). The session plays once and then holds that for good.
class PairCalibrationScenario final : public Scenario {
public:
    struct Pose {
        std::optional<BoardProp> board;
        CardProp card;
        double axisDeg = 0.0;  // direction of the tilt axis in the table plane, from +x
        double tiltDeg = 0.0;
        double liftMm = 0.0;  // board height where the panel's centre ray meets it
    };
    static constexpr double kHoldSeconds = 2.0;
    static constexpr double kMoveSeconds = 1.0;
    // The least angle between the surfaces' normals, degrees: the dialogue asks for 10 as it measures them,
    // and with the camera it guesses before any calibration it measures up to 3.3 short (see the poses).
    static constexpr double kMinTiltDifferenceDeg = 14.0;

    // Throws std::invalid_argument when the rig leaves the card no room on the table or a tilted board.
    explicit PairCalibrationScenario(const ScenarioContext& context);
    SceneState at(double seconds) const override;
    double cycleSeconds() const override;
    std::vector<Props> stillProps() const override;
    bool beginsWithTheProjector() const override { return true; }
    // The table pose first, then the board's five.
    const std::vector<Pose>& poses() const { return poses_; }
    // Start and end of the still interval of pose k, seconds into the session.
    double holdStart(int pose) const;
    double holdEnd(int pose) const { return holdStart(pose) + kHoldSeconds; }
    // When the board is gone and the card lies on the table again, for good, seconds into the session.
    double tableAgainAt() const;

private:
    std::vector<Pose> poses_;
};

}  // namespace everytouch::sim
