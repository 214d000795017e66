#include "core/finger_section.h"

#include <cmath>

namespace everytouch::core {

FingerSection fingerSection(const Eigen::Vector3d& view, const Eigen::Vector2d& pointing,
                            double halfApparentWidthMm, double thicknessPerWidth) {
    const Eigen::Vector3d ray = view.normalized();
    const Eigen::Vector2d tipward = pointing.normalized();
    const Eigen::Vector3d side(-tipward.y(), tipward.x(), 0.0);
    // The view's direction within the cross-section: the silhouette is the section's extent across it, the
    // whole width seen from above, less towards the thickness seen from the side.
    const double alongSide = ray.dot(side), alongUp = std::abs(ray.z());
    const double fromAbove = alongUp / std::hypot(alongSide, alongUp);
    const double k = thicknessPerWidth;
    FingerSection section;
    section.halfWidthMm =
        halfApparentWidthMm / std::sqrt(fromAbove * fromAbove + k * k * (1.0 - fromAbove * fromAbove));
    section.halfThicknessMm = k * section.halfWidthMm;
    // The ray through the silhouette's middle crosses the finger's axis, a half thickness above the pad; it
    // enters the finger where the section's ellipse, met along the ray, ends.
    const double enteringMm =
        1.0 / std::hypot(alongSide / section.halfWidthMm, alongUp / section.halfThicknessMm);
    section.topAbovePadMm = section.halfThicknessMm + enteringMm * alongUp;
    return section;
}

}  // namespace everytouch::core
