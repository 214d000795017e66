// The section of a finger lying on the table, from its silhouette's width and the view.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/finger_section.h"

namespace everytouch::core {
namespace {

constexpr double kHalfWidthMm = 8.0, kHalfThicknessMm = 6.0, kThicknessPerWidth = 0.75;
const double kDegree = std::numbers::pi / 180.0;

TEST(FingerSection, SeenFromAboveItsSilhouetteIsItsWidthAndItsBackIsTheTop) {
    const FingerSection section =
        fingerSection({0.0, 0.0, -1.0}, {1.0, 0.0}, kHalfWidthMm, kThicknessPerWidth);
    EXPECT_NEAR(section.halfWidthMm, kHalfWidthMm, 1e-9);
    EXPECT_NEAR(section.halfThicknessMm, kHalfThicknessMm, 1e-9);
    EXPECT_NEAR(section.topAbovePadMm, 2.0 * kHalfThicknessMm, 1e-9);
}

TEST(FingerSection, SeenAlongItTheBackIsStillTheTop) {
    // A finger pointing away from a camera 40 degrees from the vertical: the view lies in the finger's
    // vertical plane, the whole width shows, and the ray through the middle meets its back.
    const Eigen::Vector3d view(0.0, std::sin(40 * kDegree), -std::cos(40 * kDegree));
    const FingerSection section = fingerSection(view, {0.0, 1.0}, kHalfWidthMm, kThicknessPerWidth);
    EXPECT_NEAR(section.halfWidthMm, kHalfWidthMm, 1e-9);
    EXPECT_NEAR(section.topAbovePadMm, 2.0 * kHalfThicknessMm, 1e-9);
}

TEST(FingerSection, SeenFromTheSideItsSilhouetteIsNarrowerAndItsTopLower) {
    // The same finger turned across the view: the silhouette is the ellipse's extent across the ray,
    // narrower than its width, and the ray through the middle enters its flank below the back.
    for (const double angleDeg : {20.0, 40.0, 60.0}) {
        const double angle = angleDeg * kDegree;
        const Eigen::Vector3d view(0.0, std::sin(angle), -std::cos(angle));
        const double apparentMm =
            std::hypot(kHalfWidthMm * std::cos(angle), kHalfThicknessMm * std::sin(angle));
        const FingerSection section = fingerSection(view, {1.0, 0.0}, apparentMm, kThicknessPerWidth);
        EXPECT_NEAR(section.halfWidthMm, kHalfWidthMm, 1e-9) << angleDeg << " degrees";
        // Where the ray through the axis leaves the ellipse x = 8 sin t, z = 6 cos t on its way up.
        const double entering =
            1.0 / std::hypot(std::sin(angle) / kHalfWidthMm, std::cos(angle) / kHalfThicknessMm);
        EXPECT_NEAR(section.topAbovePadMm, kHalfThicknessMm + entering * std::cos(angle), 1e-9);
        EXPECT_LT(section.topAbovePadMm, 2.0 * kHalfThicknessMm);
        EXPECT_GT(section.topAbovePadMm, kHalfThicknessMm + kHalfThicknessMm * std::cos(angle));
    }
}

}  // namespace
}  // namespace everytouch::core
