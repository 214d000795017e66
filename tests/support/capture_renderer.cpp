#include "support/capture_renderer.h"

#include <cmath>

#include <opencv2/core.hpp>

#include "core/camera_model.h"
#include "core/geometry.h"

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
    const int x = static_cast<int>(std::floor(pixel.x() + 0.5)), y = static_cast<int>(std::floor(pixel.y() + 0.5));
    if (x < 0 || y < 0 || x >= projectorImage.cols || y >= projectorImage.rows)
        return 0.0;
    return projectorImage.at<uchar>(y, x) / 255.0;
}

}  // namespace

cv::Mat renderCapture(const SurfaceScene& scene, const cv::Mat& projectorImage, double noiseSigmaDn,
                      unsigned seed, int supersampling) {
    CV_Assert(projectorImage.type() == CV_8UC1 && projectorImage.size() == scene.rig.projectorSize);
    const core::CameraModel camera{scene.rig.cameraMatrix, scene.rig.cameraDistortion};
    const Eigen::Isometry3d cameraToSurface = scene.rig.tableToCamera.inverse();
    const Eigen::Vector3d normal = scene.rig.tableToCamera.rotation().col(2);
    const double normalDotOrigin = normal.dot(scene.rig.tableToCamera.translation());

    cv::Mat radiance(scene.rig.cameraSize, CV_64FC1);
    const double step = 1.0 / supersampling;
    for (int v = 0; v < radiance.rows; ++v) {
        for (int u = 0; u < radiance.cols; ++u) {
            double sum = 0.0;
            for (int j = 0; j < supersampling; ++j) {
                for (int i = 0; i < supersampling; ++i) {
                    const Eigen::Vector2d raw(u - 0.5 + (i + 0.5) * step, v - 0.5 + (j + 0.5) * step);
                    const Eigen::Vector3d ray = camera.undistortToNormalised(raw).homogeneous();
                    const double depth = normalDotOrigin / normal.dot(ray);
                    if (!(depth > 0))
                        continue;  // the ray misses the surface (looks above its horizon)
                    const Eigen::Vector3d onSurface = cameraToSurface * (depth * ray);
                    const Eigen::Vector2d pointMm = onSurface.head<2>();
                    const Eigen::Vector2d projector =
                        core::projectPoint(scene.rig.projectorMatrix, scene.rig.tableToProjector, onSurface);
                    sum += reflectance(scene, pointMm) *
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
