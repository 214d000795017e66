#include "sim/props.h"

#include <cmath>

namespace everytouch::sim {

std::array<Eigen::Vector3d, 4> stripeCorners(const CardProp& card) {
    const double x0 = (kCardLengthMm - kStripeLengthMm) / 2.0, y0 = kStripeOffsetMm;
    const double x1 = x0 + kStripeLengthMm, y1 = y0 + kStripeWidthMm;
    return {card.faceToTable * Eigen::Vector3d(x0, y0, 0), card.faceToTable * Eigen::Vector3d(x1, y0, 0),
            card.faceToTable * Eigen::Vector3d(x1, y1, 0), card.faceToTable * Eigen::Vector3d(x0, y1, 0)};
}

std::array<Eigen::Vector3d, 4> cardCorners(const CardProp& card) {
    return {card.faceToTable * Eigen::Vector3d(0, 0, 0),
            card.faceToTable * Eigen::Vector3d(kCardLengthMm, 0, 0),
            card.faceToTable * Eigen::Vector3d(kCardLengthMm, kCardWidthMm, 0),
            card.faceToTable * Eigen::Vector3d(0, kCardWidthMm, 0)};
}

std::array<Eigen::Vector3d, 4> boardCorners(const BoardProp& board) {
    const double hx = board.sizeMm.width / 2.0, hy = board.sizeMm.height / 2.0;
    return {board.faceToTable * Eigen::Vector3d(-hx, -hy, 0), board.faceToTable * Eigen::Vector3d(hx, -hy, 0),
            board.faceToTable * Eigen::Vector3d(hx, hy, 0), board.faceToTable * Eigen::Vector3d(-hx, hy, 0)};
}

CardProp cardOn(const Eigen::Isometry3d& surfaceToTable, const Eigen::Vector2d& cornerMm, double yawDeg) {
    CardProp card;
    card.faceToTable = surfaceToTable * Eigen::Translation3d(cornerMm.x(), cornerMm.y(), kCardThicknessMm) *
                       Eigen::AngleAxisd(yawDeg * M_PI / 180.0, Eigen::Vector3d::UnitZ());
    return card;
}

}  // namespace everytouch::sim
