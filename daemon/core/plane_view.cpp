#include "core/plane_view.h"

#include <cmath>

namespace everytouch::core {

int residualCount(const PlaneView& view) {
    return 4 * static_cast<int>(view.cameraPoints.size()) + (view.rectangleCorners ? 8 : 0);
}

void planeViewResiduals(const ProjectorCameraPair& pair, const Eigen::Hyperplane<double, 3>& plane,
                        const PlaneView& view, const Eigen::Isometry3d& rectangleToCamera,
                        cv::Size2d rectangleSizeMm, double* residuals) {
    for (size_t index = 0; index < view.cameraPoints.size(); ++index) {
        const Eigen::Vector2d projector = pair.projectorPixelOf(view.cameraPoints[index], plane);
        const Eigen::Vector2d camera = pair.cameraPixelOf(view.projectorPoints[index], plane);
        Eigen::Map<Eigen::Vector4d> pointResidual(residuals);
        pointResidual << projector - view.projectorPoints[index], camera - view.cameraPoints[index];
        residuals += 4;
    }
    if (!view.rectangleCorners)
        return;
    const double w = rectangleSizeMm.width, h = rectangleSizeMm.height;
    const std::array<Eigen::Vector3d, 4> corners = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(w, 0, 0),
                                                    Eigen::Vector3d(w, h, 0), Eigen::Vector3d(0, h, 0)};
    for (int corner = 0; corner < 4; ++corner) {
        Eigen::Map<Eigen::Vector2d> cornerResidual(residuals);
        cornerResidual =
            pair.camera.project(rectangleToCamera * corners[corner]) - (*view.rectangleCorners)[corner];
        residuals += 2;
    }
}

Eigen::Hyperplane<double, 3> planeOf(const Eigen::Isometry3d& frameToCamera) {
    return Eigen::Hyperplane<double, 3>(frameToCamera.rotation().col(2), frameToCamera.translation());
}

ReprojectionRms reprojectionRms(const std::vector<PlaneView>& views, const Eigen::VectorXd& residuals) {
    double cameraSum = 0.0, projectorSum = 0.0;
    int cameraCount = 0, projectorCount = 0;
    int offset = 0;
    for (const PlaneView& view : views) {
        for (size_t index = 0; index < view.cameraPoints.size(); ++index) {
            projectorSum += residuals.segment<2>(offset).squaredNorm();
            cameraSum += residuals.segment<2>(offset + 2).squaredNorm();
            offset += 4;
        }
        projectorCount += static_cast<int>(view.cameraPoints.size());
        cameraCount += static_cast<int>(view.cameraPoints.size());
        if (view.rectangleCorners) {
            cameraSum += residuals.segment<8>(offset).squaredNorm();
            offset += 8;
            cameraCount += 4;
        }
    }
    ReprojectionRms rms;
    rms.camera = cameraCount ? std::sqrt(cameraSum / cameraCount) : 0.0;
    rms.projector = projectorCount ? std::sqrt(projectorSum / projectorCount) : 0.0;
    rms.all = cameraCount + projectorCount
                  ? std::sqrt((cameraSum + projectorSum) / (cameraCount + projectorCount))
                  : 0.0;
    return rms;
}

}  // namespace everytouch::core
