#pragma once

#include <Eigen/Core>

namespace everytouch::core {

// The last bone of a finger as the camera sees it, in the table frame (mm, z up): an elliptic cylinder
// thicknessPerWidth as thick as it is wide, lying along the table. The silhouette gives its apparent width
// across the view; the height search gives the height of what the camera sees at the silhouette's middle,
// half a width behind its end. This is what lies between that and the pad, the finger's lowest point.
struct FingerSection {
    double halfWidthMm = 0.0;      // side to side
    double halfThicknessMm = 0.0;  // back to pad
    double topAbovePadMm = 0.0;    // the surface seen at the silhouette's middle, above the pad
};

// view: the ray through the silhouette's middle, from the camera (any length, pointing down). pointing: the
// finger's direction on the table, towards its tip (any length). halfApparentWidthMm: half the silhouette's
// width, across the view at the finger's distance.
FingerSection fingerSection(const Eigen::Vector3d& view, const Eigen::Vector2d& pointing,
                            double halfApparentWidthMm, double thicknessPerWidth);

}  // namespace everytouch::core
