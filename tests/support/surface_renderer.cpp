#include "support/surface_renderer.h"

#include <cmath>
#include <vector>

#include <opencv2/core.hpp>

#include "core/camera_model.h"

namespace everytouch::test {

namespace {

double reflectance(const SurfaceScene& scene, const Eigen::Vector2d& pointMm) {
    for (const DarkRectangle& rectangle : scene.rectangles) {
        const Eigen::Vector2d offset = pointMm - rectangle.originMm;
        const double c = std::cos(rectangle.angleRad), s = std::sin(rectangle.angleRad);
        const double along = c * offset.x() + s * offset.y(), across = -s * offset.x() + c * offset.y();
        if (along >= 0 && along <= rectangle.sizeMm.width && across >= 0 && across <= rectangle.sizeMm.height)
            return rectangle.albedo;
    }
    return scene.surfaceAlbedo;
}

double projectorLevel(const cv::Mat& projectorImage, const Eigen::Vector2d& pixel) {
    const int x = static_cast<int>(std::floor(pixel.x() + 0.5)),
              y = static_cast<int>(std::floor(pixel.y() + 0.5));
    if (x < 0 || y < 0 || x >= projectorImage.cols || y >= projectorImage.rows)
        return 0.0;
    return projectorImage.at<uchar>(y, x) / 255.0;
}

}  // namespace

cv::Mat renderSurface(const SurfaceScene& scene, const cv::Mat& projectorImage, double noiseSigmaDn,
                      unsigned seed, int supersampling) {
    CV_Assert(projectorImage.type() == CV_8UC1 && projectorImage.size() == scene.rig.projectorSize);
    const core::CameraModel camera{scene.rig.cameraMatrix, scene.rig.cameraDistortion};
    // Viewing rays (normalised undistorted coordinates) at the pixels' corners; inside a pixel the lens is
    // linear to far below a thousandth of a pixel, so the samples interpolate them.
    const cv::Size size = scene.rig.cameraSize;
    std::vector<Eigen::Vector2d> cornerRays((size.width + 1) * (size.height + 1));
    for (int v = 0; v <= size.height; ++v)
        for (int u = 0; u <= size.width; ++u)
            cornerRays[v * (size.width + 1) + u] = camera.undistortToNormalised({u - 0.5, v - 0.5});
    // Ray (x, y, 1) -> surface millimetres and -> projector pixels, through the plane-induced homographies.
    Eigen::Matrix3d surfaceToRay = scene.rig.tableToCamera.matrix().block<3, 3>(0, 0);
    surfaceToRay.col(2) = scene.rig.tableToCamera.translation();
    const Eigen::Matrix3d rayToSurfaceHomography = surfaceToRay.inverse();
    const Eigen::Matrix3d rayToProjector = scene.rig.tableToProjectorHomography() * rayToSurfaceHomography;

    cv::Mat radiance(size, CV_64FC1);
    const double step = 1.0 / supersampling;
    for (int v = 0; v < size.height; ++v) {
        for (int u = 0; u < size.width; ++u) {
            const Eigen::Vector2d& topLeft = cornerRays[v * (size.width + 1) + u];
            const Eigen::Vector2d& topRight = cornerRays[v * (size.width + 1) + u + 1];
            const Eigen::Vector2d& bottomLeft = cornerRays[(v + 1) * (size.width + 1) + u];
            const Eigen::Vector2d& bottomRight = cornerRays[(v + 1) * (size.width + 1) + u + 1];
            double sum = 0.0;
            for (int j = 0; j < supersampling; ++j) {
                const double fy = (j + 0.5) * step;
                const Eigen::Vector2d left = (1 - fy) * topLeft + fy * bottomLeft;
                const Eigen::Vector2d right = (1 - fy) * topRight + fy * bottomRight;
                for (int i = 0; i < supersampling; ++i) {
                    const double fx = (i + 0.5) * step;
                    const Eigen::Vector3d ray = ((1 - fx) * left + fx * right).homogeneous();
                    const Eigen::Vector3d onSurface = rayToSurfaceHomography * ray;
                    if (!(onSurface.z() > 0))
                        continue;  // the ray misses the surface (looks above its horizon)
                    const Eigen::Vector2d pointMm = onSurface.hnormalized();
                    const Eigen::Vector2d projector = (rayToProjector * ray).hnormalized();
                    sum +=
                        reflectance(scene, pointMm) *
                        (scene.ambientDn + scene.projectorGainDn * projectorLevel(projectorImage, projector));
                }
            }
            radiance.at<double>(v, u) = sum / (supersampling * supersampling);
        }
    }
    if (noiseSigmaDn > 0) {
        cv::Mat noise(radiance.size(), CV_64FC1);
        cv::RNG rng(seed);
        rng.fill(noise, cv::RNG::NORMAL, 0.0, noiseSigmaDn);
        radiance += noise;
    }
    cv::Mat image;
    radiance.convertTo(image, CV_8UC1);
    return image;
}

core::Calibration onSurface(const core::Calibration& rig, const Eigen::Isometry3d& surfaceToTable) {
    core::Calibration moved = rig;
    moved.tableToCamera = rig.tableToCamera * surfaceToTable;
    moved.tableToProjector = rig.tableToProjector * surfaceToTable;
    return moved;
}

}  // namespace everytouch::test
