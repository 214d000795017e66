#pragma once

#include <array>
#include <optional>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core/types.hpp>

namespace everytouch::sim {

// A bank card (ISO/IEC 7810 ID-1) lying face down, its magnetic stripe (ISO/IEC 7811) up: the dark rectangle
// the calibration looks for (core/table_rectangle.h).
inline constexpr double kCardLengthMm = 85.6;
inline constexpr double kCardWidthMm = 54.0;
inline constexpr double kCardThicknessMm = 0.8;
inline constexpr double kStripeLengthMm = 85.5;
inline constexpr double kStripeWidthMm = 12.5;
inline constexpr double kStripeOffsetMm = 5.5;  // from the card's long edge to the stripe

struct CardProp {
    // Card frame: origin at a corner of the card's upper face, x along its long side, y along its short side,
    // z out of the face. The stripe runs along x, kStripeOffsetMm from the edge y = 0. The lower face rests
    // on the surface under the card, kCardThicknessMm below.
    Eigen::Isometry3d faceToTable = Eigen::Isometry3d::Identity();

    bool operator==(const CardProp& other) const {
        return faceToTable.matrix() == other.faceToTable.matrix();
    }
};

// A stiff white board (an A3 foam board: large enough for the projected chessboard and the card beside it,
// light enough to hold tilted over the table).
struct BoardProp {
    // Board frame: origin at the centre of the upper face, x and y along its sides, z out of the face.
    Eigen::Isometry3d faceToTable = Eigen::Isometry3d::Identity();
    cv::Size2d sizeMm{420.0, 297.0};  // along x, along y

    bool operator==(const BoardProp& other) const {
        return faceToTable.matrix() == other.faceToTable.matrix() && sizeMm == other.sizeMm;
    }
};

// Calibration props in the scene.
struct Props {
    std::optional<CardProp> card;
    std::optional<BoardProp> board;

    bool empty() const { return !card && !board; }
    bool operator==(const Props& other) const = default;
};

// Linear reflectance (B, G, R) of the props' materials: a white plastic card back, its black stripe, a foam
// board's white paper face.
inline const Eigen::Vector3f kCardAlbedo{0.78f, 0.80f, 0.80f};
inline const Eigen::Vector3f kStripeAlbedo{0.04f, 0.04f, 0.045f};
inline const Eigen::Vector3f kBoardAlbedo{0.80f, 0.82f, 0.82f};

// The stripe's corners in table mm, in the order of its own frame: (0, 0), (length, 0), (length, width),
// (0, width), with the stripe frame's axes along the card frame's.
std::array<Eigen::Vector3d, 4> stripeCorners(const CardProp& card);
// The card's upper face's corners in table mm, (0, 0), (length, 0), (length, width), (0, width).
std::array<Eigen::Vector3d, 4> cardCorners(const CardProp& card);
// The board's upper face's corners in table mm, counter-clockwise from (-x, -y).
std::array<Eigen::Vector3d, 4> boardCorners(const BoardProp& board);

// A card resting on a surface whose upper face has the pose `surfaceToTable` (z out of the face), its corner
// at (x, y) of that surface's frame, turned by `yawDeg` about the surface's normal.
CardProp cardOn(const Eigen::Isometry3d& surfaceToTable, const Eigen::Vector2d& cornerMm, double yawDeg);

}  // namespace everytouch::sim
