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
    // Fixed-point iteration x = (x_d - tangential(x)) / radial(x), as OpenCV does, but run to convergence:
    // estimators differentiate through this function numerically, so it must be smooth to rounding.
    double x = xd, y = yd;
    constexpr int kMaxIterations = 100;
    constexpr double kConverged = 1e-15;
    for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
        const double r2 = x * x + y * y;
        const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
        const double nextX = (xd - 2.0 * p1 * x * y - p2 * (r2 + 2.0 * x * x)) / radial;
        const double nextY = (yd - p1 * (r2 + 2.0 * y * y) - 2.0 * p2 * x * y) / radial;
        const double change = std::abs(nextX - x) + std::abs(nextY - y);
        x = nextX;
        y = nextY;
        if (change < kConverged)
            break;
    }
    return {x, y};
}

Eigen::Vector2d CameraModel::undistortPixel(const Eigen::Vector2d& rawPixel) const {
    return (matrix * undistortToNormalised(rawPixel).homogeneous()).hnormalized();
}

}  // namespace everytouch::core
