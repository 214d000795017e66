#include "core/camera_model.h"

#include <cmath>

namespace everytouch::core {

Eigen::Vector2d CameraModel::project(const Eigen::Vector3d& pointInCamera) const {
    return distortNormalised(pointInCamera.hnormalized());
}

Eigen::Vector2d CameraModel::distortNormalised(const Eigen::Vector2d& normalised) const {
    const double x = normalised.x(), y = normalised.y();
    const double k1 = distortion(0), k2 = distortion(1), p1 = distortion(2), p2 = distortion(3),
                 k3 = distortion(4);
    const double r2 = x * x + y * y;
    const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
    const double xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x);
    const double yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y;
    return {matrix(0, 0) * xd + matrix(0, 1) * yd + matrix(0, 2), matrix(1, 1) * yd + matrix(1, 2)};
}

Eigen::Vector2d CameraModel::undistortToNormalised(const Eigen::Vector2d& rawPixel) const {
    const double yd = (rawPixel.y() - matrix(1, 2)) / matrix(1, 1);
    const double xd = (rawPixel.x() - matrix(0, 2) - matrix(0, 1) * yd) / matrix(0, 0);
    const double k1 = distortion(0), k2 = distortion(1), p1 = distortion(2), p2 = distortion(3),
                 k3 = distortion(4);
    // Newton's method on distort(x) = x_d: a few iterations to rounding precision where OpenCV's fixed-point
    // iteration stops after five at a tolerance. Estimators differentiate through this numerically, so it
    // must be exact and smooth.
    double x = xd, y = yd;
    constexpr int kMaxIterations = 20;
    for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
        const double r2 = x * x + y * y;
        const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
        const double radialSlope = k1 + r2 * (2.0 * k2 + 3.0 * r2 * k3);  // d radial / d r2
        const double fx = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x) - xd;
        const double fy = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y - yd;
        const double jxx = radial + 2.0 * x * x * radialSlope + 2.0 * p1 * y + 6.0 * p2 * x;
        const double jxy = 2.0 * x * y * radialSlope + 2.0 * p1 * x + 2.0 * p2 * y;
        const double jyy = radial + 2.0 * y * y * radialSlope + 6.0 * p1 * y + 2.0 * p2 * x;
        const double determinant = jxx * jyy - jxy * jxy;
        const double dx = (jyy * fx - jxy * fy) / determinant, dy = (jxx * fy - jxy * fx) / determinant;
        x -= dx;
        y -= dy;
        if (std::abs(dx) + std::abs(dy) < 1e-15 * (1.0 + std::abs(x) + std::abs(y)))
            break;
    }
    return {x, y};
}

Eigen::Vector2d CameraModel::undistortPixel(const Eigen::Vector2d& rawPixel) const {
    return (matrix * undistortToNormalised(rawPixel).homogeneous()).hnormalized();
}

Eigen::Vector2d CameraModel::distortPixel(const Eigen::Vector2d& undistortedPixel) const {
    return distortNormalised((matrix.inverse() * undistortedPixel.homogeneous()).hnormalized());
}

}  // namespace everytouch::core
